// The spring force kernels agree bit for bit: the AVX2 path must give exactly the portable path's
// forces (determinism across machines with and without it), including zero-length, compressed and
// non-finite springs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/prostate_tissue.h"
#include "rtcore/tissue/spring_forces.h"
#include "tests/support/same_bits.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

using testing::same_bits;

void expect_same_groups(const SpringIncidence& a, const SpringIncidence& b) {
  EXPECT_EQ(a.group_second_first, b.group_second_first);
  EXPECT_EQ(a.group_second, b.group_second);
  EXPECT_EQ(a.group_first_first, b.group_first_first);
  EXPECT_EQ(a.group_first, b.group_first);
}

TEST(SpringKernel, Avx2PathMatchesThePortablePathBitForBit) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  const ProstateTissueModel& model = tissue_model(1296);
  const SpringNetwork network = build_spring_network(model.mesh);
  SpringForces forces(network);
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3), speed(-0.05, 0.05), stiffness(0.1, 500.0);
  for (std::size_t s = 0; s < forces.spring_count(); ++s) forces.set_material(s, stiffness(random), 1e-3 * stiffness(random));
  std::vector<Vec3> x = model.mesh.positions, v(x.size());
  for (std::size_t n = 0; n < x.size(); ++n) {
    x[n] += Vec3(jitter(random), jitter(random), jitter(random));
    v[n] = Vec3(speed(random), speed(random), speed(random));
  }
  // A spring of zero length, one compressed below half its rest length, and a non-finite node.
  const SpringArrays& springs = forces.arrays();
  x[springs.j[10]] = x[springs.i[10]];
  x[springs.j[21]] = x[springs.i[21]] + 0.3 * (x[springs.j[21]] - x[springs.i[21]]);
  v[springs.j[33]].y = std::numeric_limits<double>::quiet_NaN();

  const std::size_t count = forces.spring_count();
  for (auto [begin, end] : {std::pair<std::size_t, std::size_t>{0, count}, {1, count - 2}, {5, 7}}) {
    SpringArrays portable = springs, simd = springs;
    const std::size_t compressed_portable = spring_forces_portable(portable, x.data(), v.data(), begin, end, portable.compressed.data());
    const std::size_t compressed_simd = spring_forces_avx2(simd, x.data(), v.data(), x.size(), begin, end, simd.compressed.data());
    ASSERT_EQ(compressed_portable, compressed_simd);
    for (std::size_t k = 0; k < compressed_portable; ++k) EXPECT_EQ(portable.compressed[k], simd.compressed[k]) << "listed " << k;
    EXPECT_TRUE(same_bits(portable.f, simd.f)) << begin << ".." << end;
    if (begin == 0) {
      EXPECT_GE(compressed_portable, 1u);
      const auto listed = portable.compressed.begin();
      EXPECT_TRUE(std::is_sorted(listed, listed + static_cast<std::ptrdiff_t>(compressed_portable)));
      EXPECT_TRUE(std::binary_search(listed, listed + static_cast<std::ptrdiff_t>(compressed_portable), 21u))
          << "the spring squeezed to 30% of its length is listed";
      EXPECT_EQ(portable.f[10].x, 0.0);
      EXPECT_TRUE(std::isnan(portable.f[33].y));
    }
  }

  // The node sums over those forces, from a non-zero start, over all nodes and over a slice.
  SpringArrays computed = springs;
  spring_forces_portable(computed, x.data(), v.data(), 0, count, computed.compressed.data());
  for (auto [begin, end] : {std::pair<std::size_t, std::size_t>{0, x.size()}, {3, x.size() - 5}}) {
    std::vector<Vec3> portable = v, simd = v;
    add_spring_sums_portable(forces.incidence(), computed.f.data(), portable.data(), begin, end);
    add_spring_sums_avx2(forces.incidence(), computed.f.data(), simd.data(), begin, end);
    EXPECT_TRUE(same_bits(portable, simd)) << begin << ".." << end;
    EXPECT_NE(portable[begin + 1], v[begin + 1]);
  }
}

TEST(SpringKernel, NodeSumsAddEachSpringOnceWithOppositeSigns) {
  // A brute-force oracle: scatter every spring's force to its two nodes in spring order.
  const ProstateTissueModel& model = tissue_model(1296);
  const SpringNetwork network = build_spring_network(model.mesh);
  SpringForces forces(network);
  for (std::size_t s = 0; s < forces.spring_count(); ++s) forces.set_material(s, 1.0 + static_cast<double>(s % 13), 1e-3);
  std::vector<Vec3> x = model.mesh.positions, v(x.size(), Vec3(0.0));
  for (std::size_t n = 0; n < x.size(); ++n) x[n] *= 1.0 + 1e-3 * static_cast<double>(n % 5);
  forces.compute(x.data(), v.data());
  std::vector<Vec3> summed(x.size(), Vec3(0.0)), scattered(x.size(), Vec3(0.0));
  forces.add_sums(summed.data());
  const SpringArrays& springs = forces.arrays();
  for (std::size_t s = 0; s < forces.spring_count(); ++s) {
    const Vec3 f(springs.f[s].x, springs.f[s].y, springs.f[s].z);
    scattered[springs.i[s]] += f;
    scattered[springs.j[s]] -= f;
  }
  for (std::size_t n = 0; n < x.size(); ++n) ASSERT_EQ(summed[n], scattered[n]) << "node " << n;
}

TEST(SpringIncidence, AppendedSpringsListedAsARebuildListsThem) {
  // Resection appends nodes, then springs whose node i is newer than any before (refinement's
  // midpoints); the incremental listing must be exactly the counting sort's, list for list, and the
  // interleaved groups, relisted only where lists grew after the first round, exactly a full rebuild's.
  const ProstateTissueModel& model = tissue_model(1296);
  const SpringNetwork network = build_spring_network(model.mesh);
  SpringForces incremental(network), rebuilt(network);
  std::size_t nodes = network.node_volume_m3.size();
  incremental.reserve(network.spring_count() + 4000, nodes + 400);
  rebuilt.reserve(network.spring_count() + 4000, nodes + 400);
  std::mt19937_64 random(11);
  for (int round = 0; round < 6; ++round) {
    const std::size_t added_nodes = 10 + 7 * static_cast<std::size_t>(round);
    incremental.add_nodes(added_nodes);
    const std::size_t first_new = incremental.spring_count();
    // Each new node gets springs to random older nodes (and some to new ones before it), by node i.
    for (std::size_t n = nodes; n < nodes + added_nodes; ++n) {
      std::uniform_int_distribution<std::uint32_t> older(0, static_cast<std::uint32_t>(n - 1));
      std::vector<std::uint32_t> others;
      for (int k = 0; k < 1 + static_cast<int>(n % 9); ++k) others.push_back(older(random));
      std::sort(others.begin(), others.end());
      others.erase(std::unique(others.begin(), others.end()), others.end());
      for (std::uint32_t j : others) {
        incremental.append(static_cast<std::uint32_t>(n), j, 1e-3);
        rebuilt.append(static_cast<std::uint32_t>(n), j, 1e-3);
      }
    }
    nodes += added_nodes;
    incremental.add_appended_to_incidence(first_new);
    rebuilt.rebuild_incidence(nodes);
    incremental.refresh_groups();
    rebuilt.refresh_groups();
    EXPECT_EQ(incremental.incidence().first_first, rebuilt.incidence().first_first) << "round " << round;
    EXPECT_EQ(incremental.incidence().second_first, rebuilt.incidence().second_first) << "round " << round;
    EXPECT_EQ(incremental.incidence().second_springs, rebuilt.incidence().second_springs) << "round " << round;
    expect_same_groups(incremental.incidence(), rebuilt.incidence());
  }
  // A round adding nodes but no spring leaves them empty.
  incremental.add_nodes(3);
  incremental.add_appended_to_incidence(incremental.spring_count());
  rebuilt.rebuild_incidence(nodes + 3);
  incremental.refresh_groups();
  rebuilt.refresh_groups();
  EXPECT_EQ(incremental.incidence().first_first, rebuilt.incidence().first_first);
  EXPECT_EQ(incremental.incidence().second_first, rebuilt.incidence().second_first);
  expect_same_groups(incremental.incidence(), rebuilt.incidence());
}

TEST(SpringIncidence, GroupsAfterEditsSumAsThePortablePass) {
  // The AVX2 node pass reads the interleaved groups (on processors that use them: spring_sums_in_groups),
  // which compute() relists after edits: after appended
  // springs, new nodes and a compaction its sums must still be the portable pass's, bit for bit.
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  const ProstateTissueModel& model = tissue_model(1296);
  const SpringNetwork network = build_spring_network(model.mesh);
  SpringForces forces(network);
  std::size_t nodes = network.node_volume_m3.size();
  forces.reserve(network.spring_count() + 100, nodes + 10);
  forces.add_nodes(5);  // five nodes, so the last group is partial and the groups move
  const std::size_t first_new = forces.spring_count();
  for (std::uint32_t n = static_cast<std::uint32_t>(nodes); n < nodes + 5; ++n) {
    for (std::uint32_t j : {1u, 7u, n - 3}) forces.append(n, j, 1e-3);
  }
  nodes += 5;
  forces.add_appended_to_incidence(first_new);
  std::vector<std::uint32_t> kept;
  for (std::uint32_t s = 0; s < forces.spring_count(); ++s) {
    if (s % 5 != 2) kept.push_back(s);
  }
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3), stiffness(0.1, 500.0);
  std::vector<Vec3> x(nodes), v(nodes, Vec3(0.01, -0.02, 0.0));
  for (std::size_t n = 0; n < nodes; ++n) x[n] = (n < model.mesh.positions.size() ? model.mesh.positions[n] : Vec3(0.0)) + Vec3(jitter(random));
  for (bool compacted : {false, true}) {
    if (compacted) forces.keep(kept, nodes);
    for (std::size_t s = 0; s < forces.spring_count(); ++s) forces.set_material(s, stiffness(random), 1e-3);
    forces.compute(x.data(), v.data());
    // Where the groups are used, they are there: the grouped pass is what this compares.
    EXPECT_EQ(forces.incidence().group_second_first.empty(), !spring_sums_in_groups());
    std::vector<Vec3> portable(nodes, Vec3(-0.0)), simd(nodes, Vec3(-0.0));
    add_spring_sums_portable(forces.incidence(), forces.arrays().f.data(), portable.data(), 0, nodes);
    add_spring_sums_avx2(forces.incidence(), forces.arrays().f.data(), simd.data(), 0, nodes);
    EXPECT_TRUE(same_bits(portable, simd)) << (compacted ? "after compaction" : "after appends");
  }
}

}  // namespace
}  // namespace resecto
