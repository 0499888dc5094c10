// A deliberately small CSV reader: comma-separated numbers under one header line, cells optionally in
// double quotes (as spreadsheets export them), every failure reported as file:line with the column.
#include "device/calibration/calibration_csv.h"

#include <algorithm>
#include <optional>
#include <string_view>
#include <utility>

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

/// The cells of one line, split at commas and trimmed. A cell in double quotes is unquoted, "" in it
/// standing for one quote (RFC 4180): spreadsheets quote the cells of a column they take for text.
Result<std::vector<std::string>> split(std::string_view line, const std::string& where) {
  std::vector<std::string> cells;
  std::size_t i = 0;
  for (;;) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::string cell;
    if (i < line.size() && line[i] == '"') {
      const std::size_t open = i++;
      for (;; ++i) {
        if (i == line.size()) return Error{where + ":" + std::to_string(open + 1) + ": the quote opened here is not closed on its line"};
        if (line[i] == '"' && !(i + 1 < line.size() && line[i + 1] == '"')) break;
        if (line[i] == '"') ++i;  // "" is one quote
        cell.push_back(line[i]);
      }
      const std::size_t close = i++;
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      if (i < line.size() && line[i] != ',') {
        return Error{where + ":" + std::to_string(i + 1) + ": '" + std::string(1, line[i]) + "' after the quote closed at column " +
                     std::to_string(close + 1) + " (a comma must follow it)"};
      }
      cells.push_back(trim(cell));
    } else {
      const std::size_t comma = std::min(line.find(',', i), line.size());
      cells.push_back(trim(std::string(line.substr(i, comma - i))));
      i = comma;
    }
    if (i >= line.size()) return cells;
    ++i;  // past the comma; a comma at the very end leaves one empty cell after it
  }
}

/// A header of one column holding ';' or tabs: a file separated by those, which this reader would take
/// for one column and then call every row's value "not a number".
std::optional<std::string> separator_problem(const std::vector<std::string>& header) {
  if (header.size() != 1) return std::nullopt;
  for (const auto& [separator, name] : {std::pair{';', "';'"}, std::pair{'\t', "a tab"}}) {
    if (header[0].find(separator) == std::string::npos) continue;
    std::string names;
    for (std::size_t start = 0; start <= header[0].size();) {
      const std::size_t end = std::min(header[0].find(separator, start), header[0].size());
      names += (names.empty() ? "'" : ", '") + trim(header[0].substr(start, end - start)) + "'";
      start = end + 1;
    }
    return "the header has no columns " + names + ", only one named '" + header[0] + "': the separator must be a comma, not " + name;
  }
  return std::nullopt;
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
    const std::string where = source + ":" + std::to_string(number);
    const Result<std::vector<std::string>> split_line = split(line, where);
    if (!split_line) return Error{split_line.error()};
    const std::vector<std::string>& cells = *split_line;
    if (table.columns.empty()) {
      if (auto problem = separator_problem(cells)) return Error{where + ": " + *problem};
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
      if (!value) return Error{where + ": column " + table.columns[c] + ": " + not_finite_kind(cells[c]) + ": '" + cells[c] + "'"};
      values.push_back(*value);
    }
    table.rows.push_back(std::move(values));
    table.lines.push_back(number);
  }
  if (table.columns.empty()) return Error{source + ": empty (expected a header line)"};
  return table;
}

Result<NumericCsv> read_numeric_csv(const std::filesystem::path& path) {
  Result<std::string> text = read_utf8_text_file(path);
  if (!text) return Error{text.error()};
  return parse_numeric_csv(*text, path.string());
}

}  // namespace resecto::device
