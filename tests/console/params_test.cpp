// `resecto params` end to end: the text table and the JSON list agree with the core's table, and
// `--set` refusals name the key or the value at fault.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "rtcore/tissue/tissue_parameters.h"
#include "tests/console/run_resecto.h"

namespace resecto::testing {
namespace {

TEST(ParamsCommand, JsonListsEveryParameterWithItsRange) {
  const CommandOutput out = run_resecto("params --json");
  ASSERT_EQ(out.exit_code, 0) << out.err;
  const nlohmann::json list = nlohmann::json::parse(out.out);
  ASSERT_TRUE(list.is_array());
  ASSERT_EQ(list.size(), tissue_parameter_specs().size());
  for (std::size_t i = 0; i < list.size(); ++i) {
    const TissueParameterSpec& spec = tissue_parameter_specs()[i];
    EXPECT_EQ(list[i]["key"], std::string(spec.key));
    EXPECT_EQ(list[i]["unit"], std::string(spec.unit));
    EXPECT_DOUBLE_EQ(list[i]["default"].get<double>(), spec.default_value);
    EXPECT_DOUBLE_EQ(list[i]["min"].get<double>(), spec.min_value);
    EXPECT_DOUBLE_EQ(list[i]["max"].get<double>(), spec.max_value);
    EXPECT_FALSE(list[i]["description"].get<std::string>().empty());
  }
}

TEST(ParamsCommand, TextTableNamesEveryKey) {
  const CommandOutput out = run_resecto("params");
  ASSERT_EQ(out.exit_code, 0) << out.err;
  for (const TissueParameterSpec& spec : tissue_parameter_specs()) EXPECT_NE(out.out.find(spec.key), std::string::npos) << spec.key;
}

TEST(ParamsCommand, SetRefusesUnknownKeysAndOutOfRangeValues) {
  const CommandOutput unknown = run_resecto("tissue indent --triangles 1296 --set stifness=10");
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.err.find("unknown parameter 'stifness'"), std::string::npos) << unknown.err;
  const CommandOutput range = run_resecto("tissue indent --triangles 1296 --set penalty_stiffness=99");
  EXPECT_NE(range.exit_code, 0);
  EXPECT_NE(range.err.find("penalty_stiffness = 99 is out of range [0.01, 10] N/mm"), std::string::npos) << range.err;
  const CommandOutput malformed = run_resecto("tissue indent --triangles 1296 --set density");
  EXPECT_NE(malformed.exit_code, 0);
  EXPECT_NE(malformed.err.find("expected KEY=VALUE"), std::string::npos) << malformed.err;
}

// Audit 6, D: "--set stiffness=+40" was "'+40' is not a number", while `--seconds +2` was read.
TEST(ParamsCommand, SetTakesALeadingPlus) {
  const CommandOutput plus = run_resecto("run --headless --triangles 1296 --seconds 0.05 --set stiffness=+40");
  EXPECT_EQ(plus.exit_code, 0) << plus.err;
}

// Audit 32, F15: a parameter given twice kept the last value without a word.
TEST(ParamsCommand, SetRefusesAParameterGivenTwice) {
  const CommandOutput twice = run_resecto("run --headless --triangles 1296 --seconds 0.05 --set stiffness=40 --set viscous_damping=20 --set stiffness=60");
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find("--set stiffness=60: stiffness is already set by --set stiffness=40; give each parameter once"), std::string::npos)
      << twice.err;
}

}  // namespace
}  // namespace resecto::testing
