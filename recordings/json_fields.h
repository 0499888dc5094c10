// Reads the fields of a JSON object by name, so that a field that is absent, of the wrong type or out
// of its type's range is refused with its path ("simulation.tissue.max_substeps: ..."). The JSON
// library's own messages name neither the field nor the file, and its unsigned conversions wrap a
// negative number silently; a header read from a damaged or hand-edited recording needs both named.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include <nlohmann/json.hpp>

namespace resecto::rec {

class JsonFields {
 public:
  /// `path` names `object` in the messages ("" for the document's root).
  JsonFields(const nlohmann::ordered_json& object, std::string path) : object_(object), path_(std::move(path)) {
    if (!object_.is_object()) fail(path_.empty() ? "the document" : path_, std::string("must be an object, not ") + object_.type_name());
  }

  /// The field `key` as T (bool, a whole number type, double, float or std::string).
  template <class T>
  T get(const char* key) const {
    const nlohmann::ordered_json& value = at(key);
    const std::string where = path_of(key);
    if constexpr (std::is_same_v<T, bool>) {
      if (!value.is_boolean()) fail(where, std::string("must be true or false, not ") + value.type_name());
      return value.get<bool>();
    } else if constexpr (std::is_integral_v<T>) {
      if (value.is_number_unsigned()) {
        const auto v = value.get<std::uint64_t>();
        if (v > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) fail(where, std::to_string(v) + " is too large");
        return static_cast<T>(v);
      }
      if (value.is_number_float()) {  // JSON has one number type: 4096.0 is a whole number too
        const auto v = value.get<double>();
        if (!(std::trunc(v) == v)) fail(where, "must be a whole number, not " + value.dump());
        if (v < static_cast<double>(std::numeric_limits<T>::min())) fail(where, value.dump() + " is too small");
        // max() + 1 is a power of two, exact as a double where max() itself is not (64 bits).
        if (!(v < static_cast<double>(std::numeric_limits<T>::max()) + 1.0)) fail(where, value.dump() + " is too large");
        return static_cast<T>(v);
      }
      if (!value.is_number_integer()) fail(where, std::string("must be a whole number, not ") + value.type_name());
      const auto v = value.get<std::int64_t>();
      if (v < static_cast<std::int64_t>(std::numeric_limits<T>::min())) fail(where, std::to_string(v) + " is too small");
      if (v > 0 && static_cast<std::uint64_t>(v) > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) fail(where, std::to_string(v) + " is too large");
      return static_cast<T>(v);
    } else if constexpr (std::is_floating_point_v<T>) {
      if (!value.is_number()) fail(where, std::string("must be a number, not ") + value.type_name());
      const auto v = value.get<double>();
      if (std::isfinite(v) && std::abs(v) > static_cast<double>(std::numeric_limits<T>::max())) fail(where, std::to_string(v) + " is too large");
      return static_cast<T>(v);
    } else {
      static_assert(std::is_same_v<T, std::string>, "a field is read as bool, a whole number, a floating-point number or a string");
      if (!value.is_string()) fail(where, std::string("must be a string, not ") + value.type_name());
      return value.get<std::string>();
    }
  }

  /// The field `key`, an array of exactly N numbers.
  template <std::size_t N>
  std::array<double, N> numbers(const char* key) const {
    const nlohmann::ordered_json& value = at(key);
    const std::string where = path_of(key);
    if (!value.is_array() || value.size() != N) fail(where, "must be an array of " + std::to_string(N) + " numbers");
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      if (!value[i].is_number()) fail(where + "[" + std::to_string(i) + "]", std::string("must be a number, not ") + value[i].type_name());
      out[i] = value[i].get<double>();
    }
    return out;
  }

  /// The field `key`, itself an object.
  JsonFields object(const char* key) const { return JsonFields(at(key), path_of(key)); }
  /// The field `key` as it is (the caller checks its shape, naming it by path_of(key)).
  const nlohmann::ordered_json& at(const char* key) const {
    const auto found = object_.find(key);
    if (found == object_.end()) fail(path_of(key), "is missing");
    return *found;
  }
  bool contains(const char* key) const { return object_.contains(key); }
  std::string path_of(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const nlohmann::ordered_json& json() const { return object_; }
  const std::string& path() const { return path_; }

  [[noreturn]] static void fail(const std::string& where, const std::string& what) { throw std::runtime_error(where + ": " + what); }

 private:
  const nlohmann::ordered_json& object_;
  std::string path_;
};

}  // namespace resecto::rec
