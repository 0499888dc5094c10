// The advice a real-time run's report gives when the machine did not keep its deadlines: none for a
// run within the machine's jitter; otherwise the fewest halvings of --substeps whose
// longer tick the run's own tick p99 fits, or a coarser gland when none does.
#include "console/headless/realtime_advice.h"

#include <gtest/gtest.h>

namespace resecto {
namespace {

// The figures as a headless report holds them, read back through realtime_figures().
RealtimeFigures figures_from_report(double miss_fraction, double tick_p99_us, double collision_hz = 60, int substeps = 16) {
  nlohmann::ordered_json r;
  r["rates_hz"] = {{"physics", collision_hz * substeps}, {"collision", collision_hz}};
  r["model"] = {{"surface_triangles", 8640}};
  r["stages"] = {{"tick", {{"median_us", tick_p99_us / 2}, {"p99_us", tick_p99_us}}}};
  r["deadlines"] = {{"ticks", 9600}, {"miss_fraction", miss_fraction}};
  return realtime_figures(r);
}

TEST(RealtimeAdvice, NoneForARunWithinTheJitter) {
  EXPECT_EQ(realtime_advice(figures_from_report(0.0, 400)), "");
  EXPECT_EQ(realtime_advice(figures_from_report(kAdviceMissFraction, 1300)), "") << "at the threshold: within it";
  EXPECT_EQ(advised_substeps(figures_from_report(kAdviceMissFraction, 1300)), 0);
}

TEST(RealtimeAdvice, NamesTheFewestHalvingsOfTheSubstepsThatFit) {
  // Measured on a 2-vCPU EPYC (Zen 3), 8640 triangles at 960 Hz: 4.8% missed, tick p99 1334 us; the
  // same run with --substeps 8 missed 0.5%.
  const std::string at_480 = realtime_advice(figures_from_report(0.048, 1334));
  EXPECT_NE(at_480.find("4.8% of the deadlines"), std::string::npos) << at_480;
  EXPECT_NE(at_480.find("--substeps 8 (480 Hz, a tick every 2083 us)"), std::string::npos) << at_480;
  EXPECT_EQ(advised_substeps(figures_from_report(0.048, 1334)), 8);
  // 0.75 of 2083 us is 1562: a p99 past it needs the next halving.
  const std::string at_240 = realtime_advice(figures_from_report(0.2, 1600));
  EXPECT_NE(at_240.find("--substeps 4 (240 Hz"), std::string::npos) << at_240;
  // Another collision rate: 100 Hz x 10 substeps, p99 2000 us: 5 substeps give 2000 us ticks (too
  // short for a 2000 us p99), 2 give 5000.
  const std::string at_200 = realtime_advice(figures_from_report(0.3, 2000, 100, 10));
  EXPECT_NE(at_200.find("--substeps 2 (200 Hz"), std::string::npos) << at_200;
}

// Audit 8, G19: a short console session missed 2.9% with a tick p99 of 212 us and was told its ticks
// "do not fit the 1042 us": misses whose ticks fit the rate are not the tick's cost.
TEST(RealtimeAdvice, NoSlowerRateWhenTheTicksFitTheRateRun) {
  const std::string advice = realtime_advice(figures_from_report(0.029, 212));
  EXPECT_EQ(advised_substeps(figures_from_report(0.029, 212)), 0);
  EXPECT_EQ(advice.find("--substeps"), std::string::npos) << advice;
  EXPECT_NE(advice.find("the ticks themselves fit (p99 212 us of the 1042 us of 960 Hz physics)"), std::string::npos) << advice;
  // 0.75 of 1042 us is 781: just past it, the halving is advised again.
  EXPECT_EQ(advised_substeps(figures_from_report(0.029, 790)), 8);
}

TEST(RealtimeAdvice, ACoarserGlandWhenNoPhysicsRateFits) {
  const std::string advice = realtime_advice(figures_from_report(0.9, 20000));
  EXPECT_EQ(advice.find("--substeps"), std::string::npos) << advice;
  EXPECT_EQ(advised_substeps(figures_from_report(0.9, 20000)), 0);
  EXPECT_NE(advice.find("a coarser gland than 8640 triangles (--triangles)"), std::string::npos) << advice;
}

}  // namespace
}  // namespace resecto
