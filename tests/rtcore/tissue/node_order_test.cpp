// The locality numbering: a true permutation that narrows how far apart a spring's nodes sit, keeps
// the mesh's geometry, and changes nothing the tissue reports in the mesh's numbering.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/indentation.h"
#include "rtcore/tissue/node_order.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

TEST(NodeOrder, IsAPermutationThatNarrowsTheSpringsSpanAndKeepsTheGeometry) {
  const ProstateTissueModel& model = tissue_model(1296);
  const std::vector<std::uint32_t> order = locality_order(model.mesh);
  ASSERT_EQ(order.size(), model.mesh.node_count());
  std::vector<std::uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k) << "not a permutation at " << k;
  EXPECT_EQ(locality_order(model.mesh), order) << "the order must be the same on every run";

  const TetMesh ordered = renumbered(model.mesh, order);
  const EdgeSpan before = edge_span(model.mesh), after = edge_span(ordered);
  EXPECT_LT(after.median * 3, before.median) << "median span " << before.median << " -> " << after.median;
  EXPECT_LT(after.max, before.max) << "max span " << before.max << " -> " << after.max;

  ASSERT_EQ(ordered.tetrahedron_count(), model.mesh.tetrahedron_count());
  for (std::size_t t = 0; t < ordered.tetrahedron_count(); ++t) {
    // The same tetrahedron, corner for corner, so orientation and volume carry over exactly.
    for (int c = 0; c < 4; ++c) ASSERT_EQ(ordered.positions[ordered.tetrahedra[t][c]], model.mesh.positions[model.mesh.tetrahedra[t][c]]);
    ASSERT_EQ(tetrahedron_volume(ordered, t), tetrahedron_volume(model.mesh, t));
    ASSERT_EQ(ordered.regions[t], model.mesh.regions[t]);
  }
}

TEST(NodeOrder, DisconnectedPiecesAreAllNumbered) {
  // Two separate tetrahedra: each component gets a contiguous block.
  TetMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {5, 0, 0}, {6, 0, 0}, {5, 1, 0}, {5, 0, 1}};
  mesh.tetrahedra = {Tetrahedron{4, 5, 6, 7}, Tetrahedron{0, 1, 2, 3}};
  mesh.regions = {TissueRegion::kAdenoma, TissueRegion::kAdenoma};
  const std::vector<std::uint32_t> order = locality_order(mesh);
  ASSERT_EQ(order.size(), 8u);
  std::vector<std::uint32_t> first(order.begin(), order.begin() + 4), second(order.begin() + 4, order.end());
  std::sort(first.begin(), first.end());
  std::sort(second.begin(), second.end());
  const bool blocks = (first == std::vector<std::uint32_t>{0, 1, 2, 3} && second == std::vector<std::uint32_t>{4, 5, 6, 7}) ||
                      (first == std::vector<std::uint32_t>{4, 5, 6, 7} && second == std::vector<std::uint32_t>{0, 1, 2, 3});
  EXPECT_TRUE(blocks);
}

TEST(NodeOrder, TheTissueReportsInTheMeshsNumberingAndMovesTheSameEitherWay) {
  const ProstateTissueModel& model = tissue_model(1296);
  TissueConfig plain;
  plain.locality_order = false;
  MassSpringTissue local(model.mesh), mesh_ordered(model.mesh, {}, plain);
  std::vector<Vec3> at_rest(model.mesh.node_count());
  local.copy_mesh_positions(at_rest);
  EXPECT_EQ(at_rest, model.mesh.positions);
  for (std::size_t n = 0; n < local.node_count(); ++n) ASSERT_EQ(local.positions()[n], model.mesh.positions[local.mesh_node(n)]);

  // The same press in both numberings: only the order of the sums differs, so the motion agrees to
  // rounding.
  for (MassSpringTissue* tissue : {&local, &mesh_ordered}) {
    const int part = tissue->tool().add_part(model.loop);
    tissue->tool().reset_pose(part, indentation_loop_pose(model.anatomy, model.loop, 0.0));
    for (int step = 0; step < 320; ++step) {
      if (step % 16 == 0) tissue->collision_step();
      tissue->tool().set_pose(part, indentation_loop_pose(model.anatomy, model.loop, 0.003 * (step + 1) / 320.0));
      (void)tissue->physics_step(1.0 / 960.0);
    }
  }
  std::vector<Vec3> a(model.mesh.node_count()), b(model.mesh.node_count());
  local.copy_mesh_positions(a);
  mesh_ordered.copy_mesh_positions(b);
  EXPECT_EQ(b, std::vector<Vec3>(mesh_ordered.positions().begin(), mesh_ordered.positions().end()));
  double largest_difference = 0.0;
  for (std::size_t n = 0; n < a.size(); ++n) largest_difference = std::max(largest_difference, glm::length(a[n] - b[n]));
  EXPECT_GT(local.max_displacement_m(), 1e-3) << "the press must move the lobe";
  EXPECT_LT(largest_difference, 1e-9) << "metres";
  EXPECT_NEAR(local.max_displacement_m(), mesh_ordered.max_displacement_m(), 1e-9);
}

}  // namespace
}  // namespace resecto
