// Checks of command-line options that CLI11's own validators get wrong or leave out, so that a command
// line that cannot be run exits 2 before anything runs (docs/commands.md, "Bad input and output files").
// Numbers: CLI11's CLI::Range compares `value < min || value > max`, which is false for NaN, so
// `--seconds nan` passed it; it also prints bounds rounded to six digits ("230.0001 is outside
// [0, 230]"). Paths: a missing input, an empty output path, an unknown procedure or parameter.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>

#include <CLI/CLI.hpp>

#include "rtcore/base/checked_number.h"
#include "rtcore/scenes/procedure.h"
#include "rtcore/tissue/tissue_parameters.h"

namespace resecto::cli {

/// Ends a command whose options, each valid alone, cannot be run together (an option of another
/// mode, a run shorter than one collision step, a reuse shift past the margin): exit 2, as for any
/// other command line that cannot be run, rather than 1, which means a failure in the inputs.
[[noreturn]] inline void refuse_command_line(const std::string& why) { throw CLI::ValidationError(why); }

/// Accepts a finite number in [lo, hi]; names the value exactly when it is not.
inline CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const std::optional<double> value = parse_finite(text);
        if (!value) return "'" + text + "' is " + not_finite_kind(text);
        if (!in_closed_range(*value, lo, hi)) {
          return exact_number(*value) + " is outside [" + exact_number(lo) + ", " + exact_number(hi) + "]";
        }
        return std::string();
      },
      "NUMBER in [" + exact_number(lo) + ", " + exact_number(hi) + "]");
}

/// Accepts a finite number not below lo (a time into a recording, which has no upper bound of its
/// own): CLI::NonNegativeNumber let NaN through and printed its upper bound as a 309-digit number.
inline CLI::Validator finite_at_least(double lo) {
  return CLI::Validator(
      [lo](std::string& text) -> std::string {
        const std::optional<double> value = parse_finite(text);
        if (!value) return "'" + text + "' is " + not_finite_kind(text);
        if (!(*value >= lo)) return exact_number(*value) + " is below " + exact_number(lo);
        return std::string();
      },
      "NUMBER >= " + exact_number(lo));
}

/// Accepts a finite number in (0, hi]: a duration, where 0 would mean nothing at all.
inline CLI::Validator positive_up_to(double hi) {
  return CLI::Validator(
      [hi](std::string& text) -> std::string {
        const std::optional<double> value = parse_finite(text);
        if (!value) return "'" + text + "' is " + not_finite_kind(text);
        if (!(*value > 0.0 && *value <= hi)) return exact_number(*value) + " is outside (0, " + exact_number(hi) + "]";
        return std::string();
      },
      "NUMBER in (0, " + exact_number(hi) + "]");
}

/// Accepts a whole number in [0, hi] written in decimal digits (an index, such as a keyframe's):
/// CLI::NonNegativeNumber printed its upper bound as a 309-digit number.
inline CLI::Validator index_up_to(std::uint64_t hi) {
  return CLI::Validator(
      [hi](std::string& text) -> std::string {
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return "'" + text + "' is not a whole number of decimal digits";
        const std::string digits = text.substr(std::min(text.find_first_not_of('0'), text.size() - 1));
        const std::string limit = std::to_string(hi);
        if (digits.size() > limit.size() || (digits.size() == limit.size() && digits > limit)) return text + " is past " + limit;
        return std::string();
      },
      "INDEX in [0, " + std::to_string(hi) + "]");
}

/// Accepts a whole number in [lo, hi] written in decimal digits, with a '-' where lo allows one, and
/// hands it on without leading zeros. The conversion underneath took "0x510" as 1296, "0300" as octal
/// (192), and refused "1296.0" as "not in range 200 to 5000000". A transform (Option::transform), not a
/// check: it rewrites the text the option converts.
inline CLI::Validator whole_in_range(std::int64_t lo, std::int64_t hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const bool negative = !text.empty() && text[0] == '-';
        const std::string digits = text.substr(negative ? 1 : 0);
        if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) {
          return "'" + text + "' is not a whole number of decimal digits";
        }
        const std::string significant = digits.substr(std::min(digits.find_first_not_of('0'), digits.size() - 1));
        const std::string range = " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
        if (significant.size() > 18) return text + range;  // past any bound an int64 holds
        const std::int64_t value = (negative ? -1 : 1) * std::stoll(significant);
        if (value < lo || value > hi) return text + range;
        text = std::to_string(value);
        return std::string();
      },
      "INT in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

/// Accepts a whole number in [0, 2^64 - 1] written in decimal digits: the conversion underneath
/// would take "-1" as 2^64 - 1 and saturate a longer number, both without a word.
inline CLI::Validator unsigned_64() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return "'" + text + "' is not a whole number of decimal digits";
        const std::string digits = text.substr(std::min(text.find_first_not_of('0'), text.size() - 1));
        if (digits.size() > 20 || (digits.size() == 20 && digits > "18446744073709551615")) return text + " is past 18446744073709551615";
        return std::string();
      },
      "UINT64");
}

/// Accepts any path but the empty one: an output given as '' would otherwise read as not given at
/// all, and the command would succeed having written nothing.
inline CLI::Validator nonempty_path() {
  return CLI::Validator([](std::string& text) -> std::string { return text.empty() ? "an empty path names no file" : std::string(); }, "FILE");
}

/// Accepts a path that exists; a missing input is a command line that cannot be run (exit 2). What
/// it is (a folder, a device, a file of the wrong kind) the command that reads it says, in its words.
inline CLI::Validator existing_path() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::error_code error;
        return std::filesystem::exists(text, error) ? std::string() : text + ": no such file";
      },
      "FILE");
}

/// Accepts a built-in procedure's name or the path of a file that exists: a name that is neither is a
/// command line that cannot be run (exit 2), like any other missing input; what the file holds is
/// checked when it is read.
inline CLI::Validator procedure_name_or_file() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (names_a_builtin_procedure(text)) {
          const Result<Procedure> builtin = builtin_procedure(text);
          return builtin ? std::string() : builtin.error();
        }
        std::error_code error;
        if (!std::filesystem::exists(text, error)) return text + ": no such file (and not a built-in procedure)";
        return std::string();
      },
      "NAME|FILE");
}

/// Accepts KEY=VALUE for a live parameter in its range (`resecto params`).
inline CLI::Validator parameter_assignment() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        TissueParameters parameters;
        const Status set = parameters.set_from_assignment(text);
        if (set) return std::string();
        // CLI11 names the option itself.
        const std::string repeated = "--set " + text + ": ";
        return set.error().starts_with(repeated) ? set.error().substr(repeated.size()) : set.error();
      },
      "KEY=VALUE");
}

}  // namespace resecto::cli
