// The core's second copy of the tissue (tissue_edit_log.h): replaying the log of resection's edits on
// a copy built alike gives the same tissue, array for array; the edited copy adopting the front's
// motion takes its positions, velocities and tool, with new nodes at their parents' midpoints.
#include <gtest/gtest.h>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/resection/resection.h"
#include "tests/support/gland_strokes.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

void expect_same_tissue(const MassSpringTissue& a, const MassSpringTissue& b) {
  ASSERT_EQ(a.node_count(), b.node_count());
  EXPECT_EQ(a.state_hash(), b.state_hash());  // positions, velocities and the topology's hash
  const TetTopology& ta = a.topology();
  const TetTopology& tb = b.topology();
  ASSERT_EQ(ta.slot_count(), tb.slot_count());
  for (std::uint32_t t = 0; t < ta.slot_count(); ++t) {
    ASSERT_EQ(ta.alive(t), tb.alive(t)) << "slot " << t;
    if (!ta.alive(t)) continue;
    EXPECT_EQ(ta.tetrahedron(t), tb.tetrahedron(t)) << "slot " << t;
    EXPECT_EQ(ta.region(t), tb.region(t)) << "slot " << t;
  }
  const SpringNetwork& na = a.network();
  const SpringNetwork& nb = b.network();
  EXPECT_EQ(na.spring_nodes, nb.spring_nodes);
  EXPECT_EQ(na.rest_length_m, nb.rest_length_m);
  EXPECT_EQ(na.volume_share_m3, nb.volume_share_m3);
  EXPECT_EQ(na.node_volume_m3, nb.node_volume_m3);
  EXPECT_EQ(a.dead_spring_count(), b.dead_spring_count());
  ASSERT_EQ(a.surface().triangles.size(), b.surface().triangles.size());
  for (std::size_t s = 0; s < a.surface().triangles.size(); ++s) {
    EXPECT_EQ(a.surface_face_owner(s), b.surface_face_owner(s)) << "face slot " << s;
    if (a.surface_face_owner(s) >= 0) {
      EXPECT_EQ(a.surface().triangles[s], b.surface().triangles[s]) << "face slot " << s;
    }
  }
  EXPECT_EQ(a.total_mass_kg(), b.total_mass_kg());
}

TEST(TissueReplay, ReplayingTheLogOfCutsRefinementsAndACompactionGivesTheSameTissue) {
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue edited(model.mesh), behind(model.mesh);
  ResectionConfig config;
  config.compact_dead_spring_fraction = 0.0;  // compact at the first step with the pedal up
  Resection resection(edited, config);
  TissueEditLog log;
  edited.set_edit_log(&log);
  cut_through_gland(resection, 6);
  ASSERT_FALSE(log.empty());
  ASSERT_GT(resection.stats().refined_tetrahedra, 0);
  ASSERT_GT(resection.stats().removed_tetrahedra, 0);
  behind.replay(log);
  expect_same_tissue(edited, behind);

  // The next round: the pedal comes up (a compaction), then more strokes; replayed in two logs.
  log.clear();
  (void)resection.step(nullptr, false, false, 1.0 / 60.0);
  ASSERT_GT(resection.stats().spring_compactions, 0);
  behind.replay(log);
  log.clear();
  cut_through_gland(resection, 6, 6);
  behind.replay(log);
  edited.set_edit_log(nullptr);
  expect_same_tissue(edited, behind);
}

TEST(TissueReplay, TheEditedCopyAdoptsTheFrontsMotionWithNewNodesAtTheirParentsMidpoints) {
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue front(model.mesh), edited(model.mesh);
  const ResectoscopeModel tool = generate_resectoscope();
  for (MassSpringTissue* copy : {&front, &edited}) copy->tool().add_part(tool.sheath);
  // The front moves (a little gravity-free sag from a kick), the other copy is cut meanwhile.
  TissueParameters changed = front.parameters();
  changed.values[static_cast<std::size_t>(TissueParameter::kStiffness)] *= 1.5;
  front.apply({0, TissueParameter::kStiffness, changed.get(TissueParameter::kStiffness)});
  for (int k = 0; k < 20; ++k) (void)front.physics_step(1.0 / 960.0);
  Resection resection(edited);
  TissueEditLog log;
  edited.set_edit_log(&log);
  cut_through_gland(resection, 4);
  edited.set_edit_log(nullptr);
  ASSERT_FALSE(log.midpoint_parents().empty());
  const std::size_t shared = front.node_count();
  ASSERT_EQ(edited.node_count(), shared + log.midpoint_parents().size());

  edited.adopt_motion(front, log.midpoint_parents(), log.orphans());
  EXPECT_EQ(edited.parameters().values, front.parameters().values) << "the command applied to the front meanwhile";
  for (std::size_t n = 0; n < shared; ++n) {
    if (edited.topology().valence(static_cast<std::uint32_t>(n)) == 0) {
      EXPECT_EQ(edited.velocities()[n], Vec3(0.0)) << "an orphan stops";
      continue;
    }
    ASSERT_EQ(edited.positions()[n], front.positions()[n]) << n;
    ASSERT_EQ(edited.velocities()[n], front.velocities()[n]) << n;
  }
  for (std::size_t k = 0; k < log.midpoint_parents().size(); ++k) {
    const auto [a, b] = log.midpoint_parents()[k];
    EXPECT_EQ(edited.positions()[shared + k], 0.5 * (edited.positions()[a] + edited.positions()[b])) << "new node " << k;
  }
  EXPECT_EQ(edited.travel_m(), front.travel_m());
  EXPECT_EQ(edited.tool().pose(0).translation, front.tool().pose(0).translation);

  // Replaying the same log on the front brings it to the edited copy's topology and state.
  front.replay(log);
  edited.adopt_motion(front, {}, {});
  expect_same_tissue(edited, front);
}

}  // namespace
}  // namespace resecto
