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

}  // namespace
}  // namespace resecto::device
