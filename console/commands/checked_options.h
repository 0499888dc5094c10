// Range checks for numeric command-line options that NaN and infinity cannot pass. CLI11's
// CLI::Range compares `value < min || value > max`, which is false for NaN, so `--seconds nan`
// passed it; it also prints bounds rounded to six digits ("230.0001 is outside [0, 230]").
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "rtcore/base/checked_number.h"

namespace resecto::cli {

/// Accepts a finite number in [lo, hi]; names the value exactly when it is not.
inline CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const std::optional<double> value = parse_finite(text);
        if (!value) return "'" + text + "' is not a finite number";
        if (!in_closed_range(*value, lo, hi)) {
          return exact_number(*value) + " is outside [" + exact_number(lo) + ", " + exact_number(hi) + "]";
        }
        return std::string();
      },
      "NUMBER in [" + exact_number(lo) + ", " + exact_number(hi) + "]");
}

/// Accepts a finite number in (0, hi]: a duration, where 0 would mean nothing at all.
inline CLI::Validator positive_up_to(double hi) {
  return CLI::Validator(
      [hi](std::string& text) -> std::string {
        const std::optional<double> value = parse_finite(text);
        if (!value) return "'" + text + "' is not a finite number";
        if (!(*value > 0.0 && *value <= hi)) return exact_number(*value) + " is outside (0, " + exact_number(hi) + "]";
        return std::string();
      },
      "NUMBER in (0, " + exact_number(hi) + "]");
}

}  // namespace resecto::cli
