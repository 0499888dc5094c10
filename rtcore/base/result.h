// Result<T>: the value of an operation that can fail at the edges (files, command line, reports),
// or a message saying what went wrong and where. [[nodiscard]] so a caller cannot drop a failure.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace resecto {

/// A failure: one human-readable line naming what is wrong and where.
struct Error {
  std::string message;
};

/// Either a T or an Error. Exceptions never cross the core's per-tick path; this does.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::move(value)) {}       // NOLINT: implicit on purpose
  Result(Error error) : state_(std::move(error)) {}   // NOLINT: implicit on purpose

  bool ok() const { return std::holds_alternative<T>(state_); }
  explicit operator bool() const { return ok(); }

  T& value() & { assert(ok()); return std::get<T>(state_); }
  const T& value() const& { assert(ok()); return std::get<T>(state_); }
  T&& value() && { assert(ok()); return std::get<T>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  const std::string& error() const { assert(!ok()); return std::get<Error>(state_).message; }

 private:
  std::variant<T, Error> state_;
};

/// Result of an operation that yields nothing but can fail.
struct Ok {};
using Status = Result<Ok>;

}  // namespace resecto
