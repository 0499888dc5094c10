// A deliberately small CSV reader: comma-separated numbers under one header line, no quoting (the
// measurement tables never need it), every failure reported as file:line with the column.
#include "device/calibration/calibration_csv.h"

#include <charconv>
#include <sstream>

#include "rtcore/base/checked_number.h"
#include "rtcore/base/text_file.h"

namespace resecto::device {
namespace {

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

}  // namespace

int NumericCsv::column(const std::string& name) const {
  for (size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == name) return static_cast<int>(i);
  }
  return -1;
}

Result<NumericCsv> parse_numeric_csv(const std::string& text, const std::string& source) {
  NumericCsv table;
  int number = 0;
  // Lines end in LF, CR LF or a lone CR: a spreadsheet's "CSV (Macintosh)" export ends them in CR.
  for (const std::string_view line : text_lines(text)) {
    ++number;
    const std::string content = trim(std::string(line));
    if (content.empty() || content[0] == '#') continue;
    const auto cells = split(content);
    const std::string where = source + ":" + std::to_string(number);
    if (table.columns.empty()) {
      table.columns = cells;
      continue;
    }
    if (cells.size() != table.columns.size()) {
      return Error{where + ": expected " + std::to_string(table.columns.size()) + " values, found " +
                   std::to_string(cells.size())};
    }
    std::vector<double> values;
    for (size_t c = 0; c < cells.size(); ++c) {
      const std::optional<double> value = parse_finite(cells[c]);
      if (!value) {
        double any = 0.0;  // "nan", "inf", "1e999" parse but are no measurement
        const auto [ptr, ec] = std::from_chars(cells[c].data(), cells[c].data() + cells[c].size(), any);
        const bool number = !cells[c].empty() && ptr == cells[c].data() + cells[c].size() && (ec == std::errc{} || ec == std::errc::result_out_of_range);
        return Error{where + ": column " + table.columns[c] + (number ? ": not a finite number: '" : ": not a number: '") + cells[c] + "'"};
      }
      values.push_back(*value);
    }
    table.rows.push_back(std::move(values));
    table.lines.push_back(number);
  }
  if (table.columns.empty()) return Error{source + ": empty (expected a header line)"};
  return table;
}

Result<NumericCsv> read_numeric_csv(const std::filesystem::path& path) {
  Result<std::string> text = read_text_file(path);
  if (!text) return Error{text.error()};
  strip_utf8_bom(*text);
  return parse_numeric_csv(*text, path.string());
}

}  // namespace resecto::device
