// `resecto tissue indent` end to end: the JSON summary's fields, a stiffer preset pushing back
// harder, and the same run twice giving the same final state hash.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/console/run_resecto.h"

namespace resecto::testing {
namespace {

nlohmann::json indent(const std::string& extra) {
  const CommandOutput out = run_resecto("tissue indent --triangles 1296 --json " + extra);
  EXPECT_EQ(out.exit_code, 0) << out.err;
  return nlohmann::json::parse(out.out);
}

TEST(TissueIndent, JsonSummaryHasTheContractFields) {
  const nlohmann::json r = indent("--depth-mm 4");
  for (const char* key : {"peak_force_n", "max_displacement_mm", "residual_mm", "finite", "max_kinetic_energy_j", "physics_step_us"}) {
    EXPECT_TRUE(r.contains(key)) << key;
  }
  EXPECT_TRUE(r["finite"].get<bool>());
  EXPECT_GT(r["peak_force_n"].get<double>(), 0.0);
  EXPECT_GT(r["max_displacement_mm"].get<double>(), 2.0);
  EXPECT_LT(r["residual_mm"].get<double>(), 0.1);
  EXPECT_GT(r["physics_step_us"]["p99"].get<double>(), 0.0);
  EXPECT_LE(r["physics_step_us"]["median"].get<double>(), r["physics_step_us"]["p99"].get<double>());
}

TEST(TissueIndent, StifferPresetPushesBackHarderAndRunsRepeat) {
  const nlohmann::json soft = indent("--set stiffness=40");
  const nlohmann::json stiff = indent("--set stiffness=80");
  EXPECT_GT(stiff["peak_force_n"].get<double>(), 1.4 * soft["peak_force_n"].get<double>());
  const nlohmann::json again = indent("--set stiffness=40");
  EXPECT_EQ(again["state_hash"], soft["state_hash"]);
}

TEST(TissueIndent, TextOutputPrintsTheCurve) {
  const CommandOutput out = run_resecto("tissue indent --triangles 1296 --depth-mm 2");
  ASSERT_EQ(out.exit_code, 0) << out.err;
  EXPECT_NE(out.out.find("depth_mm"), std::string::npos);
  EXPECT_NE(out.out.find("peak force"), std::string::npos);
}

}  // namespace
}  // namespace resecto::testing
