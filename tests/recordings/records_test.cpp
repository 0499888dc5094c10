// The steps block's metrics: every field of ProcedureMetrics comes back bit for bit, the distal
// margin's "none yet" included, and files from before it was optional (1e9 for none) read as none.
#include "recordings/records.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

namespace resecto::rec {
namespace {

StepRecord step_with(const ProcedureMetrics& metrics) {
  StepRecord step;
  step.tick = 48;
  step.state_hash = 0x0123456789abcdefull;
  step.metrics = metrics;
  return step;
}

ProcedureMetrics round_trip(const ProcedureMetrics& metrics) {
  const std::vector<StepRecord> steps = {step_with(metrics)};
  std::vector<std::uint8_t> payload;
  encode_step_block(steps, payload);
  Result<std::vector<StepRecord>> decoded = decode_step_block(payload);
  EXPECT_TRUE(decoded) << (decoded ? "" : decoded.error());
  EXPECT_EQ(decoded->size(), 1u);
  return decoded->front().metrics;
}

TEST(StepRecords, EveryMetricComesBackBitForBit) {
  ProcedureMetrics metrics;
  // A distinct value in every field, in declaration order.
  double next = 0.125;
  std::uint64_t count = 7;
  for_each_metric(metrics, [&](auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (std::is_same_v<Field, std::uint64_t>) {
      field = count++;
    } else {
      field = (next *= -1.5);
    }
  });
  const ProcedureMetrics back = round_trip(metrics);
  std::size_t fields = 0;
  std::vector<std::uint64_t> expected, got;
  for_each_metric(metrics, [&](const auto& field) {
    ++fields;
    using Field = std::decay_t<decltype(field)>;
    if constexpr (std::is_same_v<Field, std::uint64_t>) expected.push_back(field);
    else if constexpr (std::is_same_v<Field, double>) expected.push_back(std::bit_cast<std::uint64_t>(field));
    else expected.push_back(std::bit_cast<std::uint64_t>(*field));
  });
  for_each_metric(back, [&](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (std::is_same_v<Field, std::uint64_t>) got.push_back(field);
    else if constexpr (std::is_same_v<Field, double>) got.push_back(std::bit_cast<std::uint64_t>(field));
    else got.push_back(field ? std::bit_cast<std::uint64_t>(*field) : 0);
  });
  EXPECT_EQ(fields, kMetricWords);
  EXPECT_EQ(got, expected);
}

TEST(StepRecords, NoDistalMarginYetStaysNone) {
  ProcedureMetrics metrics;
  EXPECT_FALSE(round_trip(metrics).distal_margin_mm.has_value());
  metrics.distal_margin_mm = -0.0;  // a margin of zero is a margin
  ASSERT_TRUE(round_trip(metrics).distal_margin_mm.has_value());
  EXPECT_TRUE(std::signbit(*round_trip(metrics).distal_margin_mm));
  // The sentinel files held before the margin was optional.
  metrics.distal_margin_mm = 1e9;
  EXPECT_FALSE(round_trip(metrics).distal_margin_mm.has_value());
}

}  // namespace
}  // namespace resecto::rec

namespace resecto::rec {
namespace {

// A command block carrying a value the console could never have sent is refused when read, so a
// replay never applies a NaN stiffness as if it had been validated.
TEST(CommandRecords, AValueOutsideItsParameterRangeIsUndecodable) {
  std::vector<std::uint8_t> payload;
  const std::vector<ParameterCommand> good{{960, TissueParameter::kStiffness, tissue_parameter_spec(TissueParameter::kStiffness).default_value}};
  encode_command_block(good, payload);
  ASSERT_TRUE(decode_command_block(payload));
  for (const double bad : {std::nan(""), tissue_parameter_spec(TissueParameter::kStiffness).max_value * 2.0}) {
    const std::vector<ParameterCommand> commands{{960, TissueParameter::kStiffness, bad}};
    encode_command_block(commands, payload);
    const Result<std::vector<ParameterCommand>> decoded = decode_command_block(payload);
    ASSERT_FALSE(decoded) << bad;
    EXPECT_NE(decoded.error().find("tick 960"), std::string::npos) << decoded.error();
  }
}

}  // namespace
}  // namespace resecto::rec
