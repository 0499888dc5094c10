// The tissue after resection's edits against brute force: springs, volumes and surface equal a fresh
// build from the live tetrahedra; the sphere tree covers exactly the live faces; the collision pairs
// equal the brute-force pairs. Refinement alone preserves mass and the uniform-strain stiffness.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/collision/collide.h"
#include "rtcore/resection/resection.h"
#include "rtcore/tissue/springs.h"
#include "rtcore/scenes/indentation.h"
#include "tests/support/contact_oracle.h"
#include "tests/support/gland_strokes.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

/// A collision step as the core's job runs it while it cuts: a decayed tree's rebuild waits for a
/// quieter step unless the tree is overdue (TreeRebuild::kOnlyWhenOverdue).
void collision_step_deferring_rebuild(MassSpringTissue& tissue) {
  tissue.begin_collision_step();
  (void)tissue.refit_surface_tree(MassSpringTissue::TreeRebuild::kOnlyWhenOverdue);
  tissue.search_contact_candidates();
  tissue.end_collision_step();
}

TetMesh live_mesh(const MassSpringTissue& tissue) {
  TetMesh mesh;
  mesh.positions.assign(tissue.rest_positions().begin(), tissue.rest_positions().end());
  const TetTopology& topo = tissue.topology();
  for (std::uint32_t t = 0; t < topo.slot_count(); ++t) {
    if (!topo.alive(t)) continue;
    mesh.tetrahedra.push_back(topo.tetrahedron(t));
    mesh.regions.push_back(topo.region(t));
  }
  return mesh;
}

std::array<std::uint32_t, 3> canonical(const Triangle& t) {
  // The rotation that starts at the smallest corner keeps the winding.
  const int m = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
  return {t[static_cast<std::size_t>(m)], t[static_cast<std::size_t>((m + 1) % 3)], t[static_cast<std::size_t>((m + 2) % 3)]};
}

void expect_matches_fresh_build(const MassSpringTissue& tissue) {
  const TetMesh fresh = live_mesh(tissue);
  const SpringNetwork net = build_spring_network(fresh);
  std::map<std::uint64_t, double> fresh_share;
  for (std::size_t s = 0; s < net.spring_count(); ++s) {
    fresh_share[static_cast<std::uint64_t>(net.spring_nodes[2 * s]) << 32 | net.spring_nodes[2 * s + 1]] = net.volume_share_m3[s];
  }
  const SpringNetwork& live = tissue.network();
  std::size_t live_springs = 0;
  for (std::size_t s = 0; s < live.spring_count(); ++s) {
    if (!(live.volume_share_m3[s] > 0.0)) continue;
    ++live_springs;
    const std::uint32_t a = std::min(live.spring_nodes[2 * s], live.spring_nodes[2 * s + 1]);
    const std::uint32_t b = std::max(live.spring_nodes[2 * s], live.spring_nodes[2 * s + 1]);
    const auto it = fresh_share.find(static_cast<std::uint64_t>(a) << 32 | b);
    ASSERT_NE(it, fresh_share.end()) << "a spring no live tetrahedron holds: " << a << "-" << b;
    EXPECT_NEAR(live.volume_share_m3[s], it->second, 1e-12 * it->second);
    EXPECT_GT(tissue.network().volume_share_m3[s], 0.0);
  }
  EXPECT_EQ(live_springs, fresh_share.size());
  for (std::size_t n = 0; n < fresh.node_count(); ++n) EXPECT_NEAR(live.node_volume_m3[n], net.node_volume_m3[n], 1e-12 * net.node_volume_m3[n] + 1e-30);

  std::multiset<std::array<std::uint32_t, 3>> expected, actual;
  for (const Triangle& t : boundary_surface(fresh).triangles) expected.insert(canonical(t));
  const SphereTree& tree = tissue.surface_tree();
  for (std::size_t s = 0; s < tissue.surface().triangles.size(); ++s) {
    const bool live_face = tissue.surface_face_owner(s) >= 0;
    if (live_face) actual.insert(canonical(tissue.surface().triangles[s]));
    EXPECT_EQ(tree.first_leaf_of_triangle(static_cast<std::uint32_t>(s)) != SphereTree::kNoNode, live_face) << "face slot " << s;
  }
  EXPECT_EQ(actual, expected);
}

void expect_tree_covers_its_leaves(const SphereTree& tree) {
  // Every internal node's sphere holds its children's (hence every leaf below it).
  for (std::int32_t n = 0; n < tree.node_capacity(); ++n) {
    const SphereTreeLinks& link = tree.links()[static_cast<std::size_t>(n)];
    if (tree.is_leaf(n) || link.right < 0) continue;
    bool live = false;
    for (std::int32_t r = n; r >= 0; r = tree.links()[static_cast<std::size_t>(r)].parent) live = live || r == tree.root();
    if (!live) continue;
    const Sphere& s = tree.spheres()[static_cast<std::size_t>(n)];
    for (std::int32_t c : {link.left, link.right}) {
      const Sphere& child = tree.spheres()[static_cast<std::size_t>(c)];
      EXPECT_LE(length(child.center - s.center) + child.radius, s.radius * (1.0 + 1e-9) + 1e-12) << "node " << n;
    }
  }
}

/// The 1296 gland after twelve steps of one stroke: the tissue the after-cut tests examine.
class TissueEditsAfterCuts : public ::testing::Test {
 protected:
  void SetUp() override {
    cut_through_gland(resection, 12);
    ASSERT_GT(resection.stats().removed_tetrahedra, 10);
  }
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue tissue{model.mesh};
  Resection resection{tissue};
};

TEST_F(TissueEditsAfterCuts, TheTissueEqualsAFreshBuildAndTheTreeItsSurface) {
  ASSERT_GT(resection.stats().refined_tetrahedra, 10);
  expect_matches_fresh_build(tissue);
  tissue.collision_step();  // refit to the current positions
  expect_tree_covers_its_leaves(tissue.surface_tree());
}

TEST_F(TissueEditsAfterCuts, ContactCandidatesEqualBruteForce) {
  const std::vector<TriangleMesh> parts = {model.loop};
  const int loop = tissue.tool().add_part(model.loop);
  for (const double depth_mm : {0.0, 3.0}) {
    tissue.tool().reset_pose(loop, indentation_loop_pose(model.anatomy, model.loop, depth_mm * 1e-3));
    testing::expect_brute_force(tissue, parts, "after the cuts");
  }
}

TEST(TissueEdits, ContactCandidatesDoNotDependOnWhenTheTreeIsRebuilt) {
  // The collision job defers a decayed tree's rebuild while it edits (TreeRebuild::kOnlyWhenOverdue)
  // to a quieter step: the search must find the same candidates on the undecayed and decayed tree.
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue prompt(model.mesh), deferred(model.mesh);
  Resection cut_prompt(prompt), cut_deferred(deferred);
  const int loop = prompt.tool().add_part(model.loop);
  (void)deferred.tool().add_part(model.loop);
  const RigidPose pose = indentation_loop_pose(model.anatomy, model.loop, 0.002);
  prompt.tool().reset_pose(loop, pose);
  deferred.tool().reset_pose(loop, pose);
  for (int step = 0; step < 16; ++step) {
    cut_through_gland(cut_prompt, 1, step);
    cut_through_gland(cut_deferred, 1, step);
    prompt.collision_step();
    collision_step_deferring_rebuild(deferred);
    EXPECT_EQ(testing::published(deferred.tool(), true), testing::published(prompt.tool(), true)) << "step " << step;
    EXPECT_EQ(testing::published(deferred.tool(), false), testing::published(prompt.tool(), false)) << "step " << step;
    expect_tree_covers_its_leaves(deferred.surface_tree());
  }
  std::printf("rebuilds: prompt %lld, deferred %lld\n", static_cast<long long>(prompt.surface_tree_rebuilds()),
              static_cast<long long>(deferred.surface_tree_rebuilds()));
  EXPECT_LE(deferred.surface_tree_rebuilds(), prompt.surface_tree_rebuilds());
  // The quiet steps take the deferred rebuild if the tree still wants it, in stages, and then stop.
  const bool wanted = deferred.surface_tree().should_rebuild();
  const std::int64_t before = deferred.surface_tree_rebuilds();
  int stages = 0;
  while (stages < 40 && deferred.rebuild_surface_tree_if_due()) ++stages;
  EXPECT_EQ(stages > 0, wanted) << stages << " stages";
  EXPECT_EQ(deferred.surface_tree_rebuilds(), before + (wanted ? 1 : 0));
  EXPECT_FALSE(deferred.surface_tree().should_rebuild());
  EXPECT_FALSE(deferred.rebuild_surface_tree_if_due()) << "nothing more to do";
}

TEST(TissueEdits, AQuietStepsStagedRebuildKeepsTheCandidatesAndFinishesInAFewSteps) {
  // Cuts decay the tree; the quiet collision steps after them rebuild it in stages (a few levels a
  // step, MassSpringTissue::kStagedRebuildLevels) beside the search, which goes on with the decayed
  // tree meanwhile. At every step it finds exactly what a copy that keeps the decayed tree finds.
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue staged(model.mesh), decayed(model.mesh);
  Resection cut_staged(staged), cut_decayed(decayed);
  const int loop = staged.tool().add_part(model.loop);
  (void)decayed.tool().add_part(model.loop);
  const RigidPose pose = indentation_loop_pose(model.anatomy, model.loop, 0.002);
  staged.tool().reset_pose(loop, pose);
  decayed.tool().reset_pose(loop, pose);
  int strokes = 0;
  for (; strokes < 30 && !staged.surface_tree().should_rebuild(); ++strokes) {
    cut_through_gland(cut_staged, 1, strokes);
    cut_through_gland(cut_decayed, 1, strokes);
    collision_step_deferring_rebuild(staged);
    collision_step_deferring_rebuild(decayed);
  }
  ASSERT_TRUE(staged.surface_tree().should_rebuild()) << "the cuts decayed the tree (" << strokes << " strokes)";
  ASSERT_FALSE(staged.surface_tree().must_rebuild()) << "not so far that the rebuild cannot wait";
  const std::int64_t rebuilds = staged.surface_tree_rebuilds();
  const std::int32_t leaves = staged.surface_tree().leaf_count();
  int steps = 0;
  for (; steps < 40 && staged.surface_tree_rebuilds() == rebuilds; ++steps) {
    staged.begin_collision_step();
    EXPECT_TRUE(staged.refit_surface_tree(MassSpringTissue::TreeRebuild::kWhenDue)) << "step " << steps;
    staged.search_contact_candidates();
    staged.end_collision_step();
    collision_step_deferring_rebuild(decayed);  // not overdue: it keeps its decayed tree
    EXPECT_EQ(testing::published(staged.tool(), true), testing::published(decayed.tool(), true)) << "step " << steps;
    EXPECT_EQ(testing::published(staged.tool(), false), testing::published(decayed.tool(), false)) << "step " << steps;
    expect_tree_covers_its_leaves(staged.surface_tree());
  }
  EXPECT_EQ(staged.surface_tree_rebuilds(), rebuilds + 1);
  EXPECT_GE(steps, 2) << "spread over steps";
  EXPECT_LE(steps, 10) << "a 1296 gland's build has fewer than 40 levels";
  EXPECT_FALSE(staged.surface_tree().should_rebuild());
  EXPECT_EQ(staged.surface_tree().leaf_count(), leaves);
  EXPECT_FALSE(staged.refit_surface_tree(MassSpringTissue::TreeRebuild::kWhenDue)) << "nothing more to do";
  std::printf("decayed after %d strokes; the staged rebuild of %d leaves took %d collision steps\n", strokes, leaves, steps);
}

TEST(TissueEdits, CollisionPairsAfterCutsEqualBruteForce) {
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue tissue(model.mesh);
  Resection resection(tissue);
  cut_through_gland(resection, 12);
  tissue.collision_step();
  const ResectoscopeModel tool = generate_resectoscope();
  SphereTree tool_tree;
  tool_tree.build(tool.loop);
  Collider collider;
  int poses_with_pairs = 0;
  for (int k = 0; k < 24; ++k) {
    // The loop swept along the cut, where new faces are.
    RigidPose pose;
    pose.rotation = glm::dmat3(Vec3(0.0, 1.0, 0.0), Vec3(-1.0, 0.0, 0.0), Vec3(0.0, 0.0, 1.0));  // the loop hangs toward +x
    pose.translation = Vec3(0.0005 * (k % 4), 0.0, 0.010 + 0.001 * k);
    ASSERT_TRUE(collider.collide(tissue.surface_tree(), tissue.surface(), tool_tree, tool.loop, pose));
    std::vector<TrianglePair> expected;
    for (const TrianglePair& p : collide_brute_force(tissue.surface(), tool.loop, pose)) {
      if (tissue.surface_face_owner(p.tissue) >= 0) expected.push_back(p);  // free slots hold no face
    }
    const std::vector<TrianglePair> found(collider.pairs().begin(), collider.pairs().end());
    EXPECT_EQ(found, expected) << "pose " << k;
    poses_with_pairs += !expected.empty();
  }
  EXPECT_GT(poses_with_pairs, 0);
}

TEST(TissueEdits, RefinementAlonePreservesMassAndUniformStrainStiffness) {
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue tissue(model.mesh);
  auto stiffness_sum = [&] {  // sum k L0^2 = E * volume for any refinement (springs.h)
    double sum = 0.0;
    for (std::size_t i = 0; i < tissue.network().spring_count(); ++i) {
      const double share = tissue.network().volume_share_m3[i];
      if (share > 0.0) sum += edge_spring_constant(tissue.parameters().si(TissueParameter::kStiffness), share, tissue.network().rest_length_m[i]) *
                              tissue.network().rest_length_m[i] * tissue.network().rest_length_m[i];
    }
    return sum;
  };
  const double mass0 = tissue.total_mass_kg(), stiffness0 = stiffness_sum();
  TetRefiner refiner(tissue.node_capacity(), tissue.topology().tetrahedron_capacity());
  std::vector<std::uint32_t> marked;
  for (std::uint32_t t = 0; t < 400; t += 7) marked.push_back(t);
  for (int round = 0; round < 2; ++round) {
    const TetTopology& topo = tissue.topology();
    const RefinementEdit& edit = refiner.plan({tissue.rest_positions(), topo.tetrahedra(), topo.alive_flags(), topo.regions()}, marked);
    ASSERT_TRUE(tissue.can_edit(edit.new_node_parents.size(), edit.added_tetrahedra.size(), edit.removed_tetrahedra.size()));
    tissue.add_midpoint_nodes(edit.new_node_parents);
    ASSERT_FALSE(tissue.edit_tetrahedra(edit.removed_tetrahedra, edit.added_tetrahedra, edit.added_regions).refused);
    marked.assign(tissue.added_slots().begin(), tissue.added_slots().begin() + 40);
  }
  EXPECT_GT(tissue.node_count(), model.mesh.node_count());
  EXPECT_NEAR(tissue.total_mass_kg(), mass0, 1e-12 * mass0);
  EXPECT_NEAR(stiffness_sum(), stiffness0, 1e-12 * stiffness0);
  expect_matches_fresh_build(tissue);
}

// A node whose tetrahedra have all gone is no tissue: wherever it was left, the largest tissue
// displacement (the report's max_tissue_displacement_mm) does not count it. Dead nodes stay in the
// arrays until a compaction, frozen where their last tetrahedron left them.
TEST(TissueEdits, MaxDisplacementCountsOnlyNodesSomeTetrahedronHolds) {
  const ProstateTissueModel& model = tissue_model(1296);
  MassSpringTissue tissue(model.mesh);
  const TetTopology& topo = tissue.topology();
  const std::uint32_t orphan = topo.tetrahedron(0)[0];  // a mesh node
  std::vector<std::uint32_t> around;
  topo.for_each_tetrahedron_of(orphan, [&](std::uint32_t t) { around.push_back(t); });
  std::sort(around.begin(), around.end());
  ASSERT_FALSE(tissue.edit_tetrahedra(around, {}, {}).refused);
  ASSERT_EQ(topo.valence(orphan), 0u);
  std::vector<Vec3> moved(tissue.positions().begin(), tissue.positions().end());
  std::size_t orphan_at = moved.size();
  for (std::size_t i = 0; i < moved.size(); ++i) {
    if (tissue.mesh_node(i) == orphan) orphan_at = i;
  }
  ASSERT_LT(orphan_at, moved.size());
  moved[orphan_at] += Vec3(0.05, 0.0, 0.0);  // 50 mm away
  std::size_t neighbour = (orphan_at + 1) % moved.size();
  while (topo.valence(tissue.mesh_node(neighbour)) == 0) neighbour = (neighbour + 1) % moved.size();
  moved[neighbour] += Vec3(0.0, 0.002, 0.0);  // 2 mm: tissue
  tissue.set_positions(moved);
  EXPECT_NEAR(tissue.max_displacement_m(), 0.002, 1e-12);
}

}  // namespace
}  // namespace resecto
