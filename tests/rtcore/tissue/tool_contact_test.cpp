// The tool contact's clearance certificates against the brute force: a point is skipped only while
// it provably cannot touch its candidate faces, so skipping must give the same forces, bit for bit,
// as testing every candidate point at every step, however fast the loop moves.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/indentation.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

std::vector<std::uint64_t> collision_hashes(const ProstateTissueModel& model, IndentationOptions options, bool certificates) {
  std::vector<std::uint64_t> hashes;
  options.config.clearance_certificates = certificates;
  options.on_collision_step = [&](std::int64_t, std::uint64_t hash) { hashes.push_back(hash); };
  const IndentationResult result = run_indentation(model, options);
  EXPECT_TRUE(result.finite);
  EXPECT_GT(result.peak_force_n, 0.0) << "the loop pressed the tissue";
  return hashes;
}

struct Case {
  int triangles;
  double depth_mm;
  double press_s;  ///< 5 mm in 0.05 s is 100 mm/s, beyond any hand on a resectoscope
};

class ClearanceCertificates : public ::testing::TestWithParam<Case> {};

TEST_P(ClearanceCertificates, GiveTheBruteForceStateAtEveryCollisionStep) {
  const Case c = GetParam();
  IndentationOptions options;
  options.depth_m = c.depth_mm * 1e-3;
  options.press_s = c.press_s;
  options.hold_s = 0.25;
  options.withdraw_s = c.press_s;
  options.relax_s = 0.25;
  const std::vector<std::uint64_t> brute = collision_hashes(tissue_model(c.triangles), options, false);
  const std::vector<std::uint64_t> skipping = collision_hashes(tissue_model(c.triangles), options, true);
  ASSERT_EQ(brute.size(), skipping.size());
  for (std::size_t i = 0; i < brute.size(); ++i) ASSERT_EQ(brute[i], skipping[i]) << "collision step " << i;
}

INSTANTIATE_TEST_SUITE_P(Indentations, ClearanceCertificates,
                         ::testing::Values(Case{1296, 5.0, 1.0}, Case{1296, 5.0, 0.05}, Case{8640, 5.0, 0.5}, Case{8640, 3.0, 0.05}),
                         [](const auto& info) {
                           return std::to_string(info.param.triangles) + "_" + std::to_string(static_cast<int>(info.param.depth_mm)) +
                                  "mm_in_" + std::to_string(static_cast<int>(info.param.press_s * 1000)) + "ms";
                         });

TEST(ClearanceCertificates, SkipMostPointsOfAHeldIndentation) {
  // Not a speed test: it shows the certificates are doing something, counted, not timed.
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue tissue(model.mesh);
  const int part = tissue.tool().add_part(model.loop);
  tissue.tool().reset_pose(part, indentation_loop_pose(model.anatomy, model.loop, 0.0));
  for (int tick = 0; tick < 960; ++tick) {
    if (tick % 16 == 0) tissue.collision_step();
    tissue.tool().set_pose(part, indentation_loop_pose(model.anatomy, model.loop, 0.003 * std::min(1.0, tick / 480.0)));
    (void)tissue.physics_step(1.0 / 960.0);
  }
  const double evaluated = static_cast<double>(tissue.tool().points_evaluated());
  const double skipped = static_cast<double>(tissue.tool().points_skipped());
  EXPECT_GT(tissue.tool().stats().penetrating, 0) << "the loop is in the tissue";
  EXPECT_GT(skipped / (evaluated + skipped), 0.5) << evaluated << " evaluated, " << skipped << " skipped";
}

TEST(ClearanceCertificates, TissueTravelBoundsEveryNodesDisplacement) {
  // The vertex certificates trust travel_m() to bound how far any face corner moved: it must never
  // fall behind a node's actual displacement, and stays zero while nothing moves.
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue tissue(model.mesh);
  const int part = tissue.tool().add_part(model.loop);
  tissue.tool().reset_pose(part, indentation_loop_pose(model.anatomy, model.loop, -0.002));
  for (int tick = 0; tick < 64; ++tick) {
    if (tick % 16 == 0) tissue.collision_step();
    (void)tissue.physics_step(1.0 / 960.0);
  }
  EXPECT_LT(tissue.travel_m(), 1e-12) << "the loop 2 mm clear: nothing moved but the rounding allowance";
  double pressed = 0.0;
  for (int tick = 64; tick < 960; ++tick) {
    if (tick % 16 == 0) tissue.collision_step();
    const double depth = 0.004 * std::min(1.0, (tick - 64) / 300.0) - 0.002 * std::max(0.0, (tick - 600) / 180.0);
    tissue.tool().set_pose(part, indentation_loop_pose(model.anatomy, model.loop, depth));
    (void)tissue.physics_step(1.0 / 960.0);
    ASSERT_GE(tissue.travel_m(), tissue.max_displacement_m()) << "tick " << tick;
    pressed = std::max(pressed, tissue.max_displacement_m());
  }
  EXPECT_GT(pressed, 0.001) << "the loop pressed in";
}

/// Collision-step hashes of a loop pressed in and withdrawn at `press_s`, searched where it is and
/// certified at `certify_pose(tick)`; with `certificates` off, every candidate point every step.
template <class CertifyPose>
std::vector<std::uint64_t> certified_elsewhere(bool certificates, CertifyPose certify_pose, std::int64_t* skipped = nullptr) {
  const ProstateTissueModel& model = tissue_model(1296);
  TissueConfig config;
  config.clearance_certificates = certificates;
  MassSpringTissue tissue(model.mesh, TissueParameters{}, config);
  const int part = tissue.tool().add_part(model.loop);
  const auto depth_at = [](int tick) { return 0.004 * std::sin(3.14159 * tick / 480.0); };  // in and out in half a second
  tissue.tool().reset_pose(part, indentation_loop_pose(model.anatomy, model.loop, depth_at(0)));
  std::vector<std::uint64_t> hashes;
  double pressed = 0.0;
  for (int tick = 0; tick < 480; ++tick) {
    if (tick % 16 == 0) {
      tissue.begin_collision_step();
      tissue.tool().set_certify_pose(part, certify_pose(tick));
      tissue.refit_surface_tree();
      tissue.search_contact_candidates();
      tissue.end_collision_step();
      hashes.push_back(tissue.state_hash());
    }
    tissue.tool().set_pose(part, indentation_loop_pose(model.anatomy, model.loop, depth_at(tick)));
    (void)tissue.physics_step(1.0 / 960.0);
    pressed = std::max(pressed, tissue.max_displacement_m());
  }
  EXPECT_GT(pressed, 0.001) << "the loop pressed in";
  if (skipped != nullptr) *skipped = tissue.tool().points_skipped();
  return hashes;
}

TEST(ClearanceCertificates, CertifiedWhereTheToolWillBeOrAnywhereElseGiveTheBruteForceState) {
  // The search may certify its points at the pose the tool is expected at when the candidates are
  // first used (set_certify_pose): a ball clear of every face is a proof wherever it is centred, so a
  // good guess skips more and a wrong one fewer, and neither changes a force.
  const ProstateTissueModel& model = tissue_model(1296);
  const auto ahead = [&](int tick) { return indentation_loop_pose(model.anatomy, model.loop, 0.004 * std::sin(3.14159 * (tick + 16) / 480.0)); };
  const auto astray = [&](int tick) {
    RigidPose pose = indentation_loop_pose(model.anatomy, model.loop, 0.004 * std::sin(3.14159 * tick / 480.0));
    pose.translation += Vec3(0.0008, -0.0005, 0.0003);  // a millimetre off, within the 1.5 mm margin
    return pose;
  };
  const std::vector<std::uint64_t> brute = certified_elsewhere(false, ahead);
  std::int64_t skipped_ahead = 0, skipped_astray = 0;
  EXPECT_EQ(certified_elsewhere(true, ahead, &skipped_ahead), brute);
  EXPECT_EQ(certified_elsewhere(true, astray, &skipped_astray), brute);
  EXPECT_GT(skipped_ahead, 0);
}

TEST(ClearanceCertificate, HoldsOnlyWhileTheMotionCannotCloseTheGap) {
  const ToolContacts::Clearance clearance{Vec3(0.0), 1e-3, 2e-4};
  EXPECT_TRUE(clearance.holds(Vec3(0.0), 2e-4));
  EXPECT_TRUE(clearance.holds(Vec3(0.5e-3, 0.0, 0.0), 2e-4));
  EXPECT_FALSE(clearance.holds(Vec3(1e-3, 0.0, 0.0), 2e-4)) << "moved the whole clearance";
  EXPECT_FALSE(clearance.holds(Vec3(0.5e-3, 0.0, 0.0), 7e-4)) << "the tissue travelled the rest";
  EXPECT_FALSE(ToolContacts::Clearance{}.holds(Vec3(0.0), 0.0)) << "no certificate, no skip";
}

}  // namespace
}  // namespace resecto
