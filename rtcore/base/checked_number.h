// Numbers from outside (files, the command line): parsed whole, finite, inside a range, and printed
// exactly in errors. Every comparison is written so NaN fails it: `!(lo <= v && v <= hi)`, never
// `v < lo || v > hi`, which NaN passes.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include "rtcore/base/result.h"

namespace resecto {

namespace detail {
/// std::to_chars(value, format...) as text ("?" should it not fit, which no double does).
template <class... Format>
std::string chars_of(double value, Format... format) {
  char buffer[48];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value, format...);
  return error == std::errc{} ? std::string(buffer, end) : std::string("?");
}
}  // namespace detail

/// The shortest text that reads back as exactly `value` ("230.0001", never a rounded "230").
inline std::string exact_number(double value) { return detail::chars_of(value); }

/// `value` to `digits` significant digits, as printf's %g: for figures a person reads (12.5 mm^3).
inline std::string rounded_number(double value, int digits) { return detail::chars_of(value, std::chars_format::general, digits); }

/// True when `value` is a finite number in [lo, hi]; NaN is never in range.
inline bool in_closed_range(double value, double lo, double hi) { return lo <= value && value <= hi; }

/// "<what> <value> is outside [lo, hi]" or "<what> is not a finite number", or nothing when in range.
inline std::optional<std::string> range_problem(std::string_view what, double value, double lo, double hi) {
  if (!std::isfinite(value)) return std::string(what) + " is not a finite number (" + exact_number(value) + ")";
  if (in_closed_range(value, lo, hi)) return std::nullopt;
  return std::string(what) + " " + exact_number(value) + " is outside [" + exact_number(lo) + ", " + exact_number(hi) + "]";
}

/// Parses the whole of `text` as a finite double (no leading or trailing characters).
inline std::optional<double> parse_finite(std::string_view text) {
  double value = 0.0;
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);  // from_chars takes no '+'
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (!text.empty() && error == std::errc::result_out_of_range && end == text.data() + text.size()) {
    // Past a double's range: a number too small for one (1e-400) is a number, its nearest double
    // (zero or subnormal, as strtod gives it) for the range check to name; one too large is not finite.
    const std::string whole(text);
    value = std::strtod(whole.c_str(), nullptr);
    return std::isfinite(value) ? std::optional<double>(value) : std::nullopt;
  }
  if (text.empty() || error != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

/// What `text`, refused by parse_finite, is not: "not a finite number" when it reads as a number that
/// is not finite ("nan", "-inf", "1e999"), "not a number" when it reads as no number at all ("0x1p3",
/// "1.0mm", "1,5"): calling those "not finite" sent readers looking for an overflow.
inline const char* not_finite_kind(std::string_view text) {
  double value = 0.0;
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  const bool whole = !text.empty() && end == text.data() + text.size() && (error == std::errc{} || error == std::errc::result_out_of_range);
  return whole ? "not a finite number" : "not a number";
}

}  // namespace resecto
