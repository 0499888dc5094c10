// The nodes' step kernels agree bit for bit: the AVX2 path must give exactly the portable path's
// positions, velocities, step masses, fastest speed and first non-finite node, for rises and falls of
// the step mass, ranges of any length and start, and non-finite nodes (a NaN speed is passed over by
// the fastest speed, as std::max passes it over).
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "rtcore/base/cpu_features.h"
#include "rtcore/tissue/node_step_kernel.h"
#include "tests/support/same_bits.h"

namespace resecto {
namespace {

using testing::same_bits;

struct Nodes {
  std::vector<double> mass, stiffness_bound, damping_bound, step_mass;
  std::vector<Vec3> force, v, x;

  explicit Nodes(std::size_t n, std::uint64_t seed) : mass(n), stiffness_bound(n), damping_bound(n), step_mass(n), force(n), v(n), x(n) {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), positive(1e-6, 1e-3), bound(0.0, 1e4);
    for (std::size_t i = 0; i < n; ++i) {
      mass[i] = positive(random);
      stiffness_bound[i] = bound(random);
      damping_bound[i] = 1e-3 * bound(random);
      // About half the nodes' step mass rises this step, half falls or holds.
      step_mass[i] = i % 3 == 0 ? mass[i] : mass[i] + 1e-6 * bound(random);
      force[i] = Vec3(unit(random), unit(random), unit(random));
      v[i] = 0.1 * Vec3(unit(random), unit(random), unit(random));
      x[i] = 0.05 * Vec3(unit(random), unit(random), unit(random));
    }
  }
  NodeStepArrays arrays() {
    return {mass.data(), stiffness_bound.data(), damping_bound.data(), force.data(), step_mass.data(), v.data(), x.data()};
  }
};

void expect_same(const Nodes& a, const Nodes& b, const NodeStepSummary& sa, const NodeStepSummary& sb, const char* what) {
  EXPECT_TRUE(same_bits(a.x, b.x)) << what;
  EXPECT_TRUE(same_bits(a.v, b.v)) << what;
  EXPECT_TRUE(same_bits(a.step_mass, b.step_mass)) << what;
  EXPECT_EQ(std::memcmp(&sa.fastest2, &sb.fastest2, sizeof(double)), 0) << what << ": " << sa.fastest2 << " vs " << sb.fastest2;
  EXPECT_EQ(sa.first_non_finite, sb.first_non_finite) << what;
}

TEST(NodeStepKernel, Avx2PathMatchesThePortablePathBitForBit) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  const double h = 1.0 / 960.0;
  for (auto [begin, end] : {std::pair<std::size_t, std::size_t>{0, 1000}, {1, 998}, {3, 6}, {5, 5}}) {
    Nodes portable(1000, 17), simd(1000, 17);
    const NodeStepSummary sp = step_nodes_portable(portable.arrays(), h, begin, end);
    const NodeStepSummary ss = step_nodes_avx2(simd.arrays(), h, begin, end);
    expect_same(portable, simd, sp, ss, "finite nodes");
    if (begin == 0) {
      EXPECT_GT(sp.fastest2, 0.0);
      EXPECT_EQ(sp.first_non_finite, NodeStepSummary::kNone);
    }
  }
}

TEST(NodeStepKernel, NonFiniteNodesAreFoundAsThePortableLoopFindsThem) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  const double h = 1.0 / 960.0;
  Nodes portable(64, 5), simd(64, 5);
  for (Nodes* nodes : {&portable, &simd}) {
    nodes->force[42].y = std::numeric_limits<double>::quiet_NaN();  // lane 2 of its group of four
    nodes->v[57].z = std::numeric_limits<double>::infinity();
    nodes->x[61].x = 1e308;  // finite, but its sum with the rest overflows: flagged as the portable loop flags it
    nodes->x[61].y = 1e308;
  }
  const NodeStepSummary sp = step_nodes_portable(portable.arrays(), h, 0, 64);
  const NodeStepSummary ss = step_nodes_avx2(simd.arrays(), h, 0, 64);
  expect_same(portable, simd, sp, ss, "with non-finite nodes");
  EXPECT_EQ(sp.first_non_finite, 42u);
  // The NaN speed is passed over; the infinite one is the fastest.
  EXPECT_EQ(sp.fastest2, std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace resecto
