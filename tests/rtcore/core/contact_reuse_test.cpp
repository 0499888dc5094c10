// Temporal coherence of the core's contact search: a collision step whose tool and tissue have
// barely moved keeps the candidates in use instead of refitting and searching. Kept candidates must
// still hold every pair that can touch (checked against brute force at the end of every window, when
// they are stalest), the choice must be the same every run and on either thread, and a tool that
// keeps moving must go on searching.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/core/simulation.h"
#include "tests/support/contact_oracle.h"
#include "tests/support/small_simulation.h"

namespace resecto {
namespace {

using testing::small_config;

/// A hand that inserts the sheath (fast), holds it still, then creeps in and rolls slowly, the loop
/// out: a trainee looking before a stroke. The pedal stays up, so no cut forces a search.
TickInput steady_hand(std::uint64_t tick, double tick_s) {
  const double t = static_cast<double>(tick) * tick_s;
  TickInput input;
  input.tool_present = true;
  input.joints.insertion_m = 0.130 + 0.030 * std::min(t / 0.6, 1.0) + (t > 1.2 ? 0.004 * (t - 1.2) : 0.0);
  input.joints.yaw_rad = 0.02;
  input.joints.roll_rad = t > 1.2 ? 0.2 * (t - 1.2) : 0.0;
  input.joints.loop_travel_m = 0.004;
  return input;
}

/// The pairs within `reach` of each other at the current positions (brute force, tests/support/
/// contact_oracle.h) that the published candidates miss, as (kind, part, point, face) with kind 0
/// for a tissue node against a tool face and 1 for a tool vertex against a tissue face; `near` gets
/// how many pairs were within reach.
std::set<std::tuple<int, int, std::uint32_t, std::uint32_t>> missed_pairs(const Simulation& sim, const std::vector<TriangleMesh>& parts, double reach,
                                                                         int& near) {
  const MassSpringTissue& tissue = sim.tissue();
  const auto [nodes, vertices] = testing::brute_force(tissue, parts, reach, tissue.positions());
  std::set<std::tuple<int, int, std::uint32_t, std::uint32_t>> missed;
  int kind = 0;
  for (const auto* within : {&nodes, &vertices}) {
    const testing::Found published = testing::published(tissue.tool(), kind == 0);
    for (const auto& [point, faces] : *within) {
      const auto listed = published.find(point);
      for (std::uint32_t face : faces) {
        ++near;
        if (listed == published.end() || listed->second.count(face) == 0) missed.insert({kind, point.first, point.second, face});
      }
    }
    ++kind;
  }
  return missed;
}

TEST(ContactReuse, KeptCandidatesMissNoPairThatSearchingEveryStepHolds) {
  // Two runs in lockstep, one keeping its candidates while the hand holds still or creeps and one
  // searching at every collision step. At the end of every window, when kept candidates are stalest,
  // every pair within half a millimetre that the searching run holds, the keeping run holds too;
  // and keeping changes no bit of the state. (Both miss a few pairs while the sheath is pushed in at
  // 50 mm/s and the tissue swings with it: motion the margin does not cover, which the metric
  // contact_margin_exceeded_ticks counts for the tool alone. The kept ones may miss more only where
  // the tissue moved further than their margin, short by the reuse allowance, covers over the three
  // periods since their search: at 1.78 s a node the loop wire slips past springs back at ~50 mm/s.)
  SimulationConfig searching_config = small_config();
  searching_config.tissue.contact_reuse_m = 0.0;
  auto keeping = Simulation::create(small_config());
  auto searching = Simulation::create(searching_config);
  ASSERT_TRUE(keeping) << keeping.error();
  ASSERT_TRUE(searching) << searching.error();
  const ResectoscopeModel tool_model = generate_resectoscope();
  const std::vector<TriangleMesh> parts{tool_model.sheath, tool_model.loop};  // the simulation's parts 0 and 1
  const double h = (*keeping)->config().tick_s();
  const auto per_collision = static_cast<std::uint64_t>((*keeping)->config().physics_per_collision);
  constexpr double kReach = 0.0005;
  // Kept candidates were searched up to three collision periods before a window ends, and their margin
  // is short by the reuse allowance: they cover a tissue that moves less than this over those periods.
  const double covered_motion = (*keeping)->config().tissue.contact_margin_m - (*keeping)->config().tissue.contact_reuse_m - kReach;
  std::vector<std::vector<Vec3>> at_collision_ticks;  // the keeping run's positions, newest last
  int near = 0, checks_in_contact = 0, beyond_the_margin = 0;  // windows
  for (std::uint64_t tick = 0; tick < 2 * 960; ++tick) {
    if (tick % per_collision == 0) {
      const std::span<const Vec3> x = (*keeping)->tissue().positions();
      at_collision_ticks.emplace_back(x.begin(), x.end());
    }
    (*keeping)->step(steady_hand(tick, h), {});
    (*searching)->step(steady_hand(tick, h), {});
    if ((*keeping)->is_collision_tick(tick)) {
      ASSERT_EQ((*keeping)->state_hash(), (*searching)->state_hash()) << "tick " << tick;
    }
    // The last tick before the next collision tick replaces the candidates.
    if (tick % per_collision != per_collision - 1) continue;
    int near_keeping = 0, near_searching = 0;
    const auto missed_keeping = missed_pairs(**keeping, parts, kReach, near_keeping);
    const auto missed_searching = missed_pairs(**searching, parts, kReach, near_searching);
    near += near_keeping;
    // A tissue node springing back faster than the margin covers (the loop wire slipping past it at
    // ~50 mm/s) may leave the kept candidates short, as the sheath pushed in fast does the searched
    // ones: a pair only they miss must come with such motion, and such windows must be rare.
    double moved = 0.0;
    if (at_collision_ticks.size() >= 3) {
      const std::vector<Vec3>& then = at_collision_ticks[at_collision_ticks.size() - 3];
      const std::span<const Vec3> now = (*keeping)->tissue().positions();
      for (std::size_t n = 0; n < then.size(); ++n) moved = std::max(moved, glm::length(now[n] - then[n]));
    }
    bool missed_more = false;
    for (const auto& pair : missed_keeping) {
      if (missed_searching.count(pair) == 1) continue;
      missed_more = true;
      EXPECT_GT(moved, covered_motion) << "tick " << tick << ": the kept candidates miss a pair the searched ones hold, the tissue having moved "
                                       << moved * 1e3 << " mm";
    }
    if (missed_more && moved > covered_motion) ++beyond_the_margin;
    if ((*keeping)->tissue().tool().stats().penetrating > 0) ++checks_in_contact;
  }
  // The comparison means something only if the hand pressed the tissue and the candidates were kept.
  EXPECT_GT(near, 1000);
  EXPECT_GT(checks_in_contact, 60);
  EXPECT_LE(beyond_the_margin, 3) << "windows where the kept candidates missed pairs, the tissue having moved beyond what they cover";
  EXPECT_GT((*keeping)->contact_searches_reused(), 30u) << "holding still and creeping keep the candidates";
  EXPECT_GT((*keeping)->contact_searches(), 10u) << "inserting searches";
  EXPECT_EQ((*searching)->contact_searches_reused(), 0u);
  EXPECT_EQ((*keeping)->metrics().contact_margin_exceeded_ticks, 0u);
}

std::vector<std::uint64_t> hashes_of(const SimulationConfig& config, std::uint64_t& reused) {
  auto sim = Simulation::create(config);
  EXPECT_TRUE(sim) << (sim ? "" : sim.error());
  std::vector<std::uint64_t> hashes;
  for (std::uint64_t tick = 0; tick < 2 * 960; ++tick) {
    (*sim)->step(steady_hand(tick, config.tick_s()), {});
    if ((*sim)->is_collision_tick(tick)) hashes.push_back((*sim)->state_hash());
  }
  (*sim)->settle();
  reused = (*sim)->contact_searches_reused();
  return hashes;
}

TEST(ContactReuse, TheChoiceIsTheSameEveryRunAndOnEitherThread) {
  SimulationConfig inline_search = small_config();
  inline_search.collision_thread = false;
  std::uint64_t reused_a = 0, reused_b = 0, reused_c = 0;
  const auto a = hashes_of(small_config(), reused_a);
  const auto b = hashes_of(small_config(), reused_b);
  const auto c = hashes_of(inline_search, reused_c);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
  EXPECT_GT(reused_a, 0u);
  EXPECT_EQ(reused_a, reused_b);
  EXPECT_EQ(reused_a, reused_c);
}

TEST(ContactReuse, OffEveryCollisionStepSearches) {
  SimulationConfig config = small_config();
  config.tissue.contact_reuse_m = 0.0;
  std::uint64_t reused = 1;
  const auto hashes = hashes_of(config, reused);
  EXPECT_EQ(reused, 0u);
  EXPECT_EQ(hashes.size(), 120u);
}

TEST(ContactReuse, AHandThatKeepsMovingKeepsSearching) {
  // Inserting at 30 mm/s moves the tool half a millimetre a collision period, more than the reuse
  // allows: once the device's smoothing has caught up, every step searches.
  auto sim = Simulation::create(small_config());
  ASSERT_TRUE(sim) << sim.error();
  const double h = (*sim)->config().tick_s();
  std::uint64_t reused_before = 0;
  for (std::uint64_t tick = 0; tick < 960; ++tick) {
    if (tick == 192) reused_before = (*sim)->contact_searches_reused();
    TickInput input = steady_hand(0, h);
    input.joints.insertion_m = 0.130 + 0.030 * static_cast<double>(tick) * h;
    (*sim)->step(input, {});
  }
  EXPECT_EQ((*sim)->contact_searches_reused(), reused_before);
  EXPECT_GT((*sim)->contact_searches(), 40u);
}

TEST(ContactReuse, AShiftAsLargeAsTheMarginIsRefused) {
  SimulationConfig config = small_config();
  config.tissue.contact_reuse_m = config.tissue.contact_margin_m;
  const auto sim = Simulation::create(config);
  ASSERT_FALSE(sim);
  EXPECT_NE(sim.error().find("contact reuse shift"), std::string::npos) << sim.error();
  config.tissue.contact_reuse_m = -1e-4;
  EXPECT_FALSE(Simulation::create(config));
}

}  // namespace
}  // namespace resecto
