// A deterministic mutation driver: the fuzzing of libFuzzer without clang. Seeds are valid files;
// each input is a seed put through a few random edits that hostile or broken files are made of (bit
// flips, boundary integers, NaN and huge numbers, cut, repeated or deleted spans, spliced seeds).
// A fixed seed per target makes every finding reproducible by its input number.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace resecto::fuzz {

/// Inputs per target: RESECTO_FUZZ_INPUTS, else `fallback` (kept small for the everyday suite).
inline std::size_t input_count(std::size_t fallback) {
  if (const char* text = std::getenv("RESECTO_FUZZ_INPUTS")) {
    const long long n = std::atoll(text);
    if (n > 0) return static_cast<std::size_t>(n);
  }
  return fallback;
}

class Mutator {
 public:
  Mutator(std::vector<std::string> seeds, std::uint64_t seed) : seeds_(std::move(seeds)), random_(seed) {}

  /// The next input: a seed with 1 to 8 edits.
  std::string next() {
    std::string data = seeds_[pick(seeds_.size())];
    const std::size_t edits = 1 + pick(8);
    for (std::size_t e = 0; e < edits; ++e) mutate(data);
    return data;
  }

 private:
  std::size_t pick(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(random_() % n); }

  void mutate(std::string& data) {
    // Tokens that break parsers: boundary integers, non-finite and huge numbers, separators.
    static constexpr std::string_view kTokens[] = {
        "nan", "-nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "-1", "-0", "2147483647", "2147483648",
        "4294967295", "4294967296", "-2147483649", "9223372036854775807", "18446744073709551616", "1e9", "3",
        "1000000000", " ", "\n", "\r\n", "\t", "#", "/", "//", ",", ".", "e", "-", "+", "\0", "\xff", "\"", "[", "]", "{", "}",
        "solid", "endsolid", "facet normal 0 0 1", "vertex", "end_header\n", "element face 2000000000\n", "property list uchar int vertex_indices\n",
        "OFF\n", "f ", "v ", "-2", "1e200", "0x10", "00000000000000000000001"};
    const std::size_t size = data.size();
    switch (pick(size == 0 ? 2 : 11)) {
      case 0: data.insert(pick(size + 1), kTokens[pick(std::size(kTokens))]); break;
      case 1: data.insert(pick(size + 1), 1, static_cast<char>(pick(256))); break;
      case 2: data[pick(size)] ^= static_cast<char>(1u << pick(8)); break;
      case 3: data[pick(size)] = static_cast<char>(pick(256)); break;
      case 4: data.resize(pick(size + 1)); break;  // truncation anywhere
      case 5: {  // delete a span
        const std::size_t at = pick(size);
        data.erase(at, 1 + pick(std::min<std::size_t>(64, size - at)));
        break;
      }
      case 6: {  // repeat a span
        const std::size_t at = pick(size);
        const std::size_t length = 1 + pick(std::min<std::size_t>(256, size - at));
        data.insert(pick(size + 1), data.substr(at, length));
        break;
      }
      case 7: {  // replace a number-looking run with a hostile token
        std::size_t at = pick(size);
        while (at < size && !(data[at] >= '0' && data[at] <= '9')) ++at;
        std::size_t end = at;
        while (end < size && ((data[end] >= '0' && data[end] <= '9') || data[end] == '.' || data[end] == 'e' || data[end] == '-')) ++end;
        if (at < size) data.replace(at, end - at, kTokens[pick(20)]);
        break;
      }
      case 8: {  // overwrite a 4-byte little-endian word with a boundary value (binary formats)
        if (size < 4) break;
        static constexpr std::uint32_t kWords[] = {0, 1, 0x7fffffffu, 0x80000000u, 0xffffffffu, 0x7fc00000u /* NaN */, 0x7f800000u /* inf */, 1000000000u};
        const std::uint32_t word = kWords[pick(std::size(kWords))];
        const std::size_t at = pick(size - 3);
        for (int b = 0; b < 4; ++b) data[at + static_cast<std::size_t>(b)] = static_cast<char>((word >> (8 * b)) & 0xff);
        break;
      }
      case 9: {  // splice: the head of this input with the tail of another seed
        const std::string& other = seeds_[pick(seeds_.size())];
        data = data.substr(0, pick(size + 1)) + other.substr(pick(other.size() + 1));
        break;
      }
      default: {  // swap two lines' worth of bytes
        const std::size_t a = pick(size), b = pick(size);
        std::swap(data[a], data[b]);
        break;
      }
    }
  }

  std::vector<std::string> seeds_;
  std::mt19937_64 random_;
};

}  // namespace resecto::fuzz
