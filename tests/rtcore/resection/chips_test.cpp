// Chips are the pieces a cut sets free: a stroke that severs a block's unanchored top counts that
// top as one chip, with its mass, however much debris hangs from the cut's jagged edges.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "rtcore/mesh/mesh_validation.h"
#include "rtcore/resection/resection.h"
#include "tests/support/block_mesh.h"

namespace resecto {
namespace {

constexpr double kCell = 0.001, kSide = 0.016;
constexpr int kCells = 16;
constexpr int kCapsuleLayers = 4;  // the bottom 4 mm: capsule, so its outer nodes are anchored
constexpr double kCutZ = 0.008;    // the wire's height: the block's middle, in the adenoma

/// A 16 mm block of adenoma on a 4 mm capsule floor: only the floor's outer nodes are anchored.
TetMesh adenoma_on_capsule() {
  TetMesh block = block_mesh(kCells, kCells, kCells, kCell, TissueRegion::kAdenoma);
  for (std::size_t t = 0; t < block.tetrahedron_count(); ++t) {
    double z = 0.0;
    for (std::uint32_t n : block.tetrahedra[t]) z += block.positions[n].z / 4.0;
    if (z < kCapsuleLayers * kCell) block.regions[t] = TissueRegion::kCapsule;
  }
  return block;
}

/// A straight wire along x, wider than the block, at height kCutZ and depth y.
std::vector<Vec3> wire_at(double y, int samples) {
  std::vector<Vec3> wire;
  for (int i = 0; i < samples; ++i) wire.push_back({-0.002 + (kSide + 0.004) * i / (samples - 1), y, kCutZ});
  return wire;
}

double rest_volume(const TetMesh& mesh, double above_z) {
  double volume = 0.0;
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) {
    double z = 0.0;
    for (std::uint32_t n : mesh.tetrahedra[t]) z += mesh.positions[n].z / 4.0;
    if (z > above_z) volume += tetrahedron_volume(mesh, t);
  }
  return volume;
}

TEST(Chips, AStrokeThatSeversTheBlocksTopCountsItAsOneChipWithItsMass) {
  const TetMesh block = adenoma_on_capsule();
  MassSpringTissue tissue(block);
  ResectionConfig config;
  config.channel_origin = Vec3(-1.0);  // no channel wall in a block
  Resection resection(tissue, config);
  // Across the whole block and out of its far face, over eight collision steps, as a loop's stroke.
  const double radius = 0.0008, start = -0.002, travel = kSide + 0.004;
  constexpr int kSteps = 8;
  SweptVolume sweep(17);
  for (int step = 0; step < kSteps; ++step) {
    sweep.set(wire_at(start + travel * step / kSteps, 17), wire_at(start + travel * (step + 1) / kSteps, 17), radius);
    (void)resection.step(&sweep, true, false, 1.0 / 60.0);
  }
  const ResectionStats& stats = resection.stats();
  const auto adenoma = static_cast<std::size_t>(TissueRegion::kAdenoma);
  // The top, from the slab's upper face up, left whole: one piece, however jagged its underside.
  EXPECT_EQ(stats.chips, 1);
  const double top = rest_volume(block, kCutZ + radius + kCell);
  EXPECT_GE(stats.chip_m3[adenoma], top) << "the chip holds the whole top";
  EXPECT_LE(stats.chip_m3[adenoma], rest_volume(block, kCutZ - radius - kCell));
  // What stays is the floor and the adenoma under the cut, one closed surface.
  const TriangleMesh surface = tissue.live_surface(true);
  Result<SurfaceReport> report = validate_closed_surface(surface);
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->components, 1);
  EXPECT_LT(report->volume_m3, rest_volume(block, -1.0) - top);
}

TEST(Chips, AStrokeThatSeversNothingCutsNoChip) {
  // The same wire from outside the block to half-way through it: a groove, nothing set free.
  const TetMesh block = adenoma_on_capsule();
  MassSpringTissue tissue(block);
  ResectionConfig config;
  config.channel_origin = Vec3(-1.0);
  Resection resection(tissue, config);
  SweptVolume sweep(17);
  sweep.set(wire_at(-0.002, 17), wire_at(kSide / 2.0, 17), 0.0008);
  const ResectionStep cut = resection.step(&sweep, true, false, 1.0 / 60.0);
  EXPECT_GT(cut.cut_tetrahedra, 0);
  EXPECT_EQ(resection.stats().chips, 0);
  Result<SurfaceReport> report = validate_closed_surface(tissue.live_surface(true));
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->components, 1);
}

}  // namespace
}  // namespace resecto
