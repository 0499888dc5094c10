// Numeric CSV tables of caliper measurements: a header naming the columns, then rows of numbers;
// errors name the file, line and column.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "rtcore/base/result.h"

namespace resecto::device {

/// A parsed table: the header's column names and, per data row, its numbers and 1-based line number.
struct NumericCsv {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  std::vector<int> lines;

  /// Index of column `name`, or -1.
  int column(const std::string& name) const;
};

/// Parses `text` (from `source`); blank lines and lines starting with '#' are skipped.
Result<NumericCsv> parse_numeric_csv(const std::string& text, const std::string& source);

/// Reads and parses a CSV file.
Result<NumericCsv> read_numeric_csv(const std::filesystem::path& path);

}  // namespace resecto::device
