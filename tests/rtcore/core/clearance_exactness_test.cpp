// The contact's clearance certificates skip work, never change the result: the built-in procedures,
// which press the tissue hard enough to fold its surface and cut it, give the brute-force state
// (every candidate point tested every step) at every collision step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "rtcore/core/simulation.h"
#include "tests/support/procedure_input.h"

namespace resecto {
namespace {

struct HashTrail {
  std::vector<std::uint64_t> hashes;  // at every collision step
  std::int64_t points_skipped = 0;
  std::int64_t points_evaluated = 0;
};

HashTrail run_procedure(const std::string& name, int triangles, bool certificates, double seconds) {
  SimulationConfig config;
  config.prostate_triangles = triangles;
  config.tissue.clearance_certificates = certificates;
  auto sim = Simulation::create(config);
  EXPECT_TRUE(sim) << (sim ? "" : sim.error());
  Result<Procedure> procedure = builtin_procedure(name);
  EXPECT_TRUE(procedure) << (procedure ? "" : procedure.error());
  HashTrail trail;
  if (!sim || !procedure) return trail;
  const double tick_s = config.tick_s();
  const auto ticks = static_cast<std::uint64_t>(std::llround(std::min(seconds, procedure->duration_s()) / tick_s));
  for (std::uint64_t tick = 0; tick < ticks; ++tick) {
    (*sim)->step(procedure_input(*procedure, tick, tick_s), {});
    if ((*sim)->is_collision_tick(tick)) trail.hashes.push_back((*sim)->state_hash());
  }
  trail.points_skipped = (*sim)->tissue().tool().points_skipped();
  trail.points_evaluated = (*sim)->tissue().tool().points_evaluated();
  return trail;
}

void expect_brute_force_state(const std::string& name, int triangles, double seconds) {
  const HashTrail skipping = run_procedure(name, triangles, true, seconds);
  const HashTrail brute_force = run_procedure(name, triangles, false, seconds);
  ASSERT_EQ(skipping.hashes.size(), brute_force.hashes.size());
  ASSERT_FALSE(skipping.hashes.empty());
  std::size_t first_difference = skipping.hashes.size();
  for (std::size_t i = 0; i < skipping.hashes.size() && first_difference == skipping.hashes.size(); ++i) {
    if (skipping.hashes[i] != brute_force.hashes[i]) first_difference = i;
  }
  EXPECT_EQ(first_difference, skipping.hashes.size()) << name << " at " << triangles << " triangles left the brute-force state at collision step "
                                                      << first_difference << " of " << skipping.hashes.size();
  EXPECT_GT(skipping.points_skipped, 0) << "the certificates skipped nothing: the comparison proves nothing";
  std::printf("%s %d: %zu collision steps compared; %lld point tests run, %lld skipped (brute force: %lld run)\n", name.c_str(), triangles,
              skipping.hashes.size(), static_cast<long long>(skipping.points_evaluated), static_cast<long long>(skipping.points_skipped),
              static_cast<long long>(brute_force.points_evaluated));
}

TEST(ClearanceExactness, DemoAt8640GivesTheBruteForceStateAtEveryCollisionStep) { expect_brute_force_state("demo", 8640, 1e9); }

TEST(ClearanceExactness, TurpAt1296GivesTheBruteForceStateAtEveryCollisionStep) { expect_brute_force_state("turp", 1296, 1e9); }

}  // namespace
}  // namespace resecto
