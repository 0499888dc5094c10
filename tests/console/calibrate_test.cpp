// `resecto device calibrate` end to end: caliper CSVs in, residuals printed, a calibration file the
// reader accepts out; refusals exit non-zero with one line naming the file and line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/console/run_resecto.h"

namespace {

using resecto::testing::run_resecto;
using resecto::testing::scratch_directory;

void write_text(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

/// Sheath: position = -0.22 * counts + 815 with +-0.5 count alternation.
std::string sheath_csv() {
  std::string text = "position_mm,potentiometer_counts\n";
  for (int i = 0; i <= 23; ++i) {
    const double position = 10.0 * i;
    text += std::to_string(position) + "," + std::to_string((position - 815.0) / -0.22 + (i % 2 ? 0.5 : -0.5)) + "\n";
  }
  return text;
}

/// Hall: two channels, rising and non-linear, measured every millimetre from 0 to 36.
std::string hall_csv() {
  std::string text = "# caliper sweep\nposition_mm,hall_a_counts,hall_b_counts\n";
  for (int i = 0; i <= 36; ++i) {
    const double x = i;
    text += std::to_string(x) + "," + std::to_string(2000 + 30 * x + 0.05 * x * x * x) + "," +
            std::to_string(1500 + 10 * x) + "\n";
  }
  return text;
}

TEST(CalibrateCommand, FitsBothSensorsPrintsResidualsAndWritesTheFile) {
  const auto dir = scratch_directory("calibrate_ok");
  write_text(dir / "sheath.csv", sheath_csv());
  write_text(dir / "hall.csv", hall_csv());
  const auto out = dir / "device.json";
  const auto r = run_resecto("device calibrate --sheath " + (dir / "sheath.csv").string() + " --hall " +
                             (dir / "hall.csv").string() + " -o " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("sheath: 24 measurements, gain -0.2200"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("residual_mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("hall: 37 measurements, table of 74 points"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrote "), std::string::npos);

  const auto file = nlohmann::json::parse(resecto::testing::read_text(out));
  EXPECT_EQ(file["format"], "resecto-calibration");
  EXPECT_NEAR(file["sheath"]["gain_mm_per_count"].get<double>(), -0.22, 1e-4);
  EXPECT_EQ(file["sheath"]["max_mm"].get<double>(), 230.0);
  const auto& sums = file["hall_table"]["hall_sum_counts"];
  ASSERT_EQ(sums.size(), 74u);
  // Table point at 10 mm: 3500 + 40 * 10 + 0.05 * 1000 = 3950 (measured exactly there).
  EXPECT_EQ(sums[20].get<int>(), 3950);
  EXPECT_EQ(file["registration"]["translation_mm"][2].get<double>(), -150.0);

  // --json prints one object with the fits; --base keeps the file's other part.
  const auto j = run_resecto("device calibrate --json --base " + out.string() + " --hall " +
                             (dir / "hall.csv").string() + " -o " + (dir / "again.json").string());
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto summary = nlohmann::json::parse(j.out);
  EXPECT_EQ(summary["hall"]["points"], 74);
  EXPECT_FALSE(summary.contains("sheath"));
  const auto again = nlohmann::json::parse(resecto::testing::read_text(dir / "again.json"));
  EXPECT_EQ(again["sheath"], file["sheath"]);
}

TEST(CalibrateCommand, RefusesDataThatCannotGiveAMonotoneTable) {
  const auto dir = scratch_directory("calibrate_refuse");
  std::string hall = hall_csv();
  const auto at = hall.find("\n20.000000,");
  hall.replace(at + 1, hall.find('\n', at + 1) - at - 1, "20.000000,1000,1000");  // file line 23
  write_text(dir / "hall.csv", hall);
  const auto out = dir / "device.json";
  const auto r = run_resecto("device calibrate --hall " + (dir / "hall.csv").string() + " -o " + out.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("hall.csv:23"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("monotone"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CalibrateCommand, NamesBadInputs) {
  const auto dir = scratch_directory("calibrate_bad");
  write_text(dir / "sheath.csv", "position_mm,potentiometer_counts\n0,3686\n10,oops\n");
  const auto r = run_resecto("device calibrate --sheath " + (dir / "sheath.csv").string() + " -o " +
                             (dir / "x.json").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("sheath.csv:3: column potentiometer_counts: not a number"), std::string::npos) << r.err;
  const auto none = run_resecto("device calibrate -o " + (dir / "x.json").string());
  EXPECT_NE(none.exit_code, 0);
  EXPECT_NE(none.err.find("--sheath"), std::string::npos) << none.err;
  EXPECT_EQ(run_resecto("device calibrate --help").exit_code, 0);
  // Rows at one position (different readings): the coverage is what is wrong, not a gain of 0
  // "outside +-0.5 mm/count" (audit 8, G12).
  write_text(dir / "one_place.csv", "position_mm,potentiometer_counts\n10,3700\n10,3600\n10,3500\n");
  const auto one_place = run_resecto("device calibrate --sheath " + (dir / "one_place.csv").string() + " -o " + (dir / "x.json").string());
  EXPECT_EQ(one_place.exit_code, 1);
  EXPECT_NE(one_place.err.find("every sheath measurement is at the same position (10.000 mm)"), std::string::npos) << one_place.err;
}

}  // namespace
