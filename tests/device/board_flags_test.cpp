// The board's fault flags as the host counts them: each report's LP3500_STATUS_* bits, one count per
// report and flag, so a run's report says which encoder lost counts and how often the board lost data.
#include "device/link/board_flags.h"

#include <gtest/gtest.h>

#include <array>

#include "resecto/lp3500_protocol.h"

namespace resecto {
namespace {

TEST(BoardFlagCounts, CountsEachFlagOfEachReport) {
  BoardFlagCounts counts;
  counts.count(0);
  EXPECT_EQ(counts.illegal_transitions, (std::array<std::uint64_t, 3>{0, 0, 0}));
  counts.count(LP3500_STATUS_ILLEGAL_ENCODER_0 | LP3500_STATUS_ILLEGAL_ENCODER_2);
  counts.count(LP3500_STATUS_ILLEGAL_ENCODER_2 | LP3500_STATUS_OVERRUN | LP3500_STATUS_LOOP_CLAMPED);
  counts.count(LP3500_STATUS_SHEATH_CLAMPED | LP3500_STATUS_STALL | LP3500_STATUS_NO_ADC_SAMPLE | LP3500_STATUS_DEFAULT_CALIBRATION);
  EXPECT_EQ(counts.illegal_transitions[0], 1u);
  EXPECT_EQ(counts.illegal_transitions[1], 0u);
  EXPECT_EQ(counts.illegal_transitions[2], 2u);
  EXPECT_EQ(counts.overruns, 1u);
  EXPECT_EQ(counts.loop_clamped, 1u);
  EXPECT_EQ(counts.sheath_clamped, 1u);
  EXPECT_EQ(counts.stalls, 1u);
  EXPECT_EQ(counts.no_adc_sample, 1u);
}

}  // namespace
}  // namespace resecto
