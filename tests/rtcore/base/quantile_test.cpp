// Nearest-rank quantiles against their definition counted out by hand, and at the edges.
#include "rtcore/base/quantile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace resecto {
namespace {

TEST(Quantile, NearestRankOfSmallLists) {
  // 1..10 shuffled: the q-quantile is ceil(10 q), at least 1.
  const std::vector<double> samples = {7, 3, 10, 1, 5, 9, 2, 8, 4, 6};
  EXPECT_EQ(quantile(samples, 0.0), 1.0);
  EXPECT_EQ(quantile(samples, 0.1), 1.0);
  EXPECT_EQ(quantile(samples, 0.11), 2.0);
  EXPECT_EQ(quantile(samples, 0.5), 5.0);  // the lower median of an even count
  EXPECT_EQ(quantile(samples, 0.95), 10.0);
  EXPECT_EQ(quantile(samples, 1.0), 10.0);
  EXPECT_EQ(quantile({4.0, 1.0, 2.0}, 0.5), 2.0);  // the middle of an odd count
  EXPECT_EQ(quantile({42.0}, 0.99), 42.0);
}

TEST(Quantile, EmptyAndOutOfRangeFractions) {
  EXPECT_EQ(quantile({}, 0.5), 0.0);
  const std::vector<double> samples = {3, 1, 2};
  EXPECT_EQ(quantile(samples, -1.0), 1.0);
  EXPECT_EQ(quantile(samples, 2.0), 3.0);
  EXPECT_EQ(quantile(samples, std::numeric_limits<double>::quiet_NaN()), 1.0);
}

TEST(Quantile, AtLeastAFractionQOfTheSamplesAreAtOrBelowIt) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> value(-5.0, 5.0);
  for (int n : {1, 2, 7, 100, 1001}) {
    std::vector<double> samples(static_cast<std::size_t>(n));
    for (double& s : samples) s = value(rng);
    for (double q : {0.01, 0.25, 0.5, 0.9, 0.99}) {
      const double x = quantile(samples, q);
      std::size_t at_or_below = 0, below = 0;
      for (double s : samples) {
        at_or_below += s <= x;
        below += s < x;
      }
      // x is a sample; at least q n samples are at or below it, fewer than q n strictly below.
      EXPECT_GE(static_cast<double>(at_or_below), q * n) << "n " << n << " q " << q;
      EXPECT_LT(static_cast<double>(below), q * n) << "n " << n << " q " << q;
    }
  }
}

}  // namespace
}  // namespace resecto
