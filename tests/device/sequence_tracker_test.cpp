// SequenceTracker: gaps, duplicates, late arrivals, the 32-bit wrap, stale reports and restarts.
#include "device/link/sequence_tracker.h"

#include <gtest/gtest.h>

namespace resecto {
namespace {

struct Observed {
  SequenceVerdict verdict;
  std::uint64_t unwrapped;
  std::uint64_t gap;
};

Observed observe(SequenceTracker& t, std::uint32_t s) {
  Observed o{};
  o.verdict = t.observe(s, o.unwrapped, o.gap);
  return o;
}

TEST(SequenceTracker, ClassifiesGapsDuplicatesAndLateReports) {
  SequenceTracker t;
  EXPECT_EQ(observe(t, 10).verdict, SequenceVerdict::kFirst);
  EXPECT_EQ(observe(t, 11).verdict, SequenceVerdict::kNext);
  const Observed jump = observe(t, 15);
  EXPECT_EQ(jump.verdict, SequenceVerdict::kNext);
  EXPECT_EQ(jump.gap, 3u);
  EXPECT_EQ(observe(t, 15).verdict, SequenceVerdict::kDuplicate);
  EXPECT_EQ(observe(t, 11).verdict, SequenceVerdict::kDuplicate);
  EXPECT_EQ(observe(t, 13).verdict, SequenceVerdict::kLate);
  EXPECT_EQ(observe(t, 13).verdict, SequenceVerdict::kDuplicate);  // late once, then a duplicate
  EXPECT_EQ(observe(t, 9).verdict, SequenceVerdict::kLate);         // before the first: still placeable
  const Observed next = observe(t, 16);
  EXPECT_EQ(next.gap, 0u);
  EXPECT_EQ(next.unwrapped - jump.unwrapped, 1u);
}

TEST(SequenceTracker, UnwrapsAcrossTheThirtyTwoBitBoundary) {
  SequenceTracker t;
  (void)observe(t, 0xFFFFFFFEu);
  const Observed a = observe(t, 0xFFFFFFFFu);
  const Observed b = observe(t, 0u);
  const Observed c = observe(t, 2u);
  EXPECT_EQ(b.verdict, SequenceVerdict::kNext);
  EXPECT_EQ(b.unwrapped, a.unwrapped + 1);
  EXPECT_EQ(c.gap, 1u);
  EXPECT_EQ(observe(t, 0xFFFFFFFFu).verdict, SequenceVerdict::kDuplicate);
  EXPECT_EQ(observe(t, 1u).verdict, SequenceVerdict::kLate);
}

TEST(SequenceTracker, WindowSlotsAreReusedCleanly) {
  // After the newest moves a full window on, old slots must not read as "seen".
  SequenceTracker t;
  (void)observe(t, 1000);
  for (std::uint32_t s = 1002; s < 1000 + 5 * SequenceTracker::kWindow; s += 2) {
    ASSERT_EQ(observe(t, s).verdict, SequenceVerdict::kNext) << s;
    ASSERT_EQ(observe(t, s - 1).verdict, SequenceVerdict::kLate) << s - 1;
  }
}

TEST(SequenceTracker, FarBehindIsARestartNearZeroElseStale) {
  SequenceTracker t;
  (void)observe(t, 500'000);
  EXPECT_EQ(observe(t, 500'000 - 2 * SequenceTracker::kWindow).verdict, SequenceVerdict::kStale);
  EXPECT_EQ(observe(t, 3).verdict, SequenceVerdict::kRestart);
  EXPECT_EQ(observe(t, 4).verdict, SequenceVerdict::kNext);
  EXPECT_EQ(observe(t, 3).verdict, SequenceVerdict::kDuplicate);
}

}  // namespace
}  // namespace resecto
