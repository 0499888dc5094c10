// The calibration tables' CSV reader: its line endings and where its errors point.
#include "device/calibration/calibration_csv.h"

#include <gtest/gtest.h>

namespace resecto::device {
namespace {

// A spreadsheet's "CSV (Macintosh)" export ends lines in a lone CR: read by LF it was one header line
// with no rows (audit 24, F11).
TEST(CalibrationCsv, LinesEndInLfCrLfOrCr) {
  for (const char* ending : {"\n", "\r\n", "\r"}) {
    const std::string text = std::string("position_mm,potentiometer_counts") + ending + "# measured" + ending + "0,100" + ending + ending +
                             "10, 400" + ending;
    const Result<NumericCsv> table = parse_numeric_csv(text, "sheath.csv");
    ASSERT_TRUE(table) << table.error();
    ASSERT_EQ(table->rows.size(), 2u);
    EXPECT_EQ(table->rows[1][1], 400.0);
    EXPECT_EQ(table->lines[1], 5);  // the line a residual or an error names
    const Result<NumericCsv> bad = parse_numeric_csv(text + "20,x" + ending, "sheath.csv");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), "sheath.csv:6: column potentiometer_counts: not a number: 'x'");
  }
}

// Audit 6, A: a spreadsheet quotes the cells of a column it takes for text ("0","3686"), and those
// were "not a number".
TEST(CalibrationCsv, ReadsDoubleQuotedCells) {
  const Result<NumericCsv> table =
      parse_numeric_csv("\"position_mm\",\"potentiometer_counts\"\n\"0\", \"3686.41\" \n10,\"3641\"\n", "s.csv");
  ASSERT_TRUE(table) << table.error();
  EXPECT_EQ(table->columns, (std::vector<std::string>{"position_mm", "potentiometer_counts"}));
  EXPECT_EQ(table->rows, (std::vector<std::vector<double>>{{0.0, 3686.41}, {10.0, 3641.0}}));
  const Result<NumericCsv> one_cell = parse_numeric_csv("a,b\n\"1,5\",2\n", "s.csv");
  ASSERT_FALSE(one_cell);
  EXPECT_EQ(one_cell.error(), "s.csv:2: column a: not a number: '1,5'");
  const Result<NumericCsv> quote_in_quotes = parse_numeric_csv("a,\"say \"\"b\"\"\"\n1,2\n", "s.csv");
  ASSERT_TRUE(quote_in_quotes) << quote_in_quotes.error();
  EXPECT_EQ(quote_in_quotes->columns[1], "say \"b\"");
  const Result<NumericCsv> open = parse_numeric_csv("a,b\n1,\"2\n", "s.csv");
  ASSERT_FALSE(open);
  EXPECT_EQ(open.error(), "s.csv:2:3: the quote opened here is not closed on its line");
  const Result<NumericCsv> after = parse_numeric_csv("a,b\n1,\"2\"3\n", "s.csv");
  ASSERT_FALSE(after);
  EXPECT_EQ(after.error(), "s.csv:2:6: '3' after the quote closed at column 5 (a comma must follow it)");
}

// Audit 6, A: a ';'-separated file was one column, and its first row "not a number".
TEST(CalibrationCsv, SaysTheSeparatorMustBeAComma) {
  const Result<NumericCsv> semicolons = parse_numeric_csv("position_mm;potentiometer_counts\n0;3686\n", "s.csv");
  ASSERT_FALSE(semicolons);
  EXPECT_EQ(semicolons.error(),
            "s.csv:1: the header has no columns 'position_mm', 'potentiometer_counts', only one named 'position_mm;potentiometer_counts': "
            "the separator must be a comma, not ';'");
  const Result<NumericCsv> tabs = parse_numeric_csv("position_mm\tpotentiometer_counts\n0\t3686\n", "s.csv");
  ASSERT_FALSE(tabs);
  EXPECT_NE(tabs.error().find("the separator must be a comma, not a tab"), std::string::npos) << tabs.error();
  EXPECT_TRUE(parse_numeric_csv("position_mm\n0\n", "s.csv"));  // one column is still a table
}

}  // namespace
}  // namespace resecto::device
