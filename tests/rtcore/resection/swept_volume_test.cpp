// The geometry oracle: a straight stroke of a straight wire through a block removes close to the
// analytic volume the inflated wire sweeps, at two resolutions, with refinement on (and off, reported).
#include <gtest/gtest.h>

#include <limits>
#include <numbers>

#include <cstdio>

#include "rtcore/mesh/mesh_validation.h"
#include "rtcore/resection/resection.h"
#include "tests/support/block_mesh.h"

namespace resecto {
namespace {

TEST(SweptVolume, PathDistanceOfAStraightRibbon) {
  SweptVolume sweep(8);
  const Vec3 from[2] = {{0.0, 0.0, 0.0}, {0.006, 0.0, 0.0}};
  const Vec3 to[2] = {{0.0, 0.008, 0.0}, {0.006, 0.008, 0.0}};
  sweep.set(from, to, 0.001);
  EXPECT_NEAR(sweep.path_distance({0.003, 0.004, 0.0005}), 0.0005, 1e-15);
  EXPECT_NEAR(sweep.path_distance({0.008, 0.004, 0.0}), 0.002, 1e-15);
  EXPECT_TRUE(sweep.contains({0.003, -0.0009, 0.0}));
  EXPECT_FALSE(sweep.contains({0.003, -0.0011, 0.0}));
  EXPECT_NEAR(sweep.bounds().max.y, 0.009, 1e-15);
}

/// A 16 mm block of cubes of `cell_m` (every boundary face its outer surface), its tissue and a
/// resection of it, cut by a 6 mm wire along x at the block's mid-height.
struct CutBlock {
  static constexpr double kSide = 0.016, kSpan = 0.006;
  CutBlock(double cell_m, const ResectionConfig& config)
      : block(block_mesh(cells(cell_m), cells(cell_m), cells(cell_m), cell_m)), tissue(block), resection(tissue, no_channel(config)) {}
  /// The wire's `samples` points at depth y.
  static std::vector<Vec3> wire_at(double y, int samples) {
    std::vector<Vec3> wire;
    for (int i = 0; i < samples; ++i) wire.push_back({0.005 + kSpan * i / (samples - 1), y, 0.008});
    return wire;
  }
  static int cells(double cell_m) { return static_cast<int>(std::lround(kSide / cell_m)); }
  static ResectionConfig no_channel(ResectionConfig config) {
    config.channel_origin = Vec3(-1.0);
    return config;
  }
  TetMesh block;
  MassSpringTissue tissue;
  Resection resection;
};

/// Cuts the block with the wire, radius 1 mm, moving across itself right through it (from 2 mm
/// before its face to 2 mm past the far one, so the cut opens from the surface as the loop's does),
/// in `steps` collision steps; returns the removed volume over the analytic one.
double stroke_ratio(double cell_m, bool refine, int steps, std::size_t max_marked, std::int64_t* refined) {
  ResectionConfig config;
  config.refine = refine;
  config.max_refined_per_step = max_marked;
  CutBlock cut(cell_m, config);
  const double r = 0.001, side = CutBlock::kSide, start = -0.002, travel = side + 0.004;
  SweptVolume sweep(13);
  for (int step = 0; step < steps; ++step) {
    sweep.set(CutBlock::wire_at(start + travel * step / steps, 13), CutBlock::wire_at(start + travel * (step + 1) / steps, 13), r);
    (void)cut.resection.step(&sweep, true, false, 1.0 / 60.0);
  }
  *refined = cut.resection.stats().refined_tetrahedra;
  const double removed = cut.resection.stats().removed_m3[static_cast<std::size_t>(TissueRegion::kCapsule)];
  // Inside the block the sweep is the slab and the half-cylinders along the wire's two ends, over
  // the block's whole depth: the rounded ends of the stroke lie outside it.
  const double inside = 2.0 * r * CutBlock::kSpan * side + std::numbers::pi * r * r * side;
  return removed / inside;
}

TEST(SweptVolume, AStraightStrokeRemovesTheAnalyticVolumeAtTwoResolutions) {
  // The rule's accuracy: the whole stroke in one step, refinement uncapped (the default cap of
  // ResectionConfig::max_refined_per_step is the real-time budget's; it leaves part of so long a
  // single step unrefined).
  constexpr std::size_t kUncapped = std::numeric_limits<std::size_t>::max();
  for (double cell : {0.002, 0.001}) {
    std::int64_t refined_on = 0, refined_off = 0;
    const double on = stroke_ratio(cell, true, 1, kUncapped, &refined_on);
    const double off = stroke_ratio(cell, false, 1, kUncapped, &refined_off);
    std::printf("cells %.1f mm: removed / analytic = %.3f with refinement (%lld split), %.3f without\n", cell * 1e3, on,
                static_cast<long long>(refined_on), off);
    EXPECT_NEAR(on, 1.0, 0.15) << "cell " << cell;
    EXPECT_EQ(refined_off, 0);
  }
}

TEST(SweptVolume, AWireBuriedInTheTissueCutsNoVoidUntilItsCutReachesTheSurface) {
  // The wire sunk 4 mm into a 16 mm block (the penalty contact lets it) with the pedal down: its
  // sweep takes the centroids of tetrahedra that the surface does not reach, and none may go, or a
  // closed void would be left inside. The next sweep, from there out through the block's face,
  // opens the cut from the surface, and then both go.
  CutBlock cut(0.001, {});
  SweptVolume sweep(7);
  sweep.set(CutBlock::wire_at(0.005, 7), CutBlock::wire_at(0.007, 7), 0.0008);
  const ResectionStep buried = cut.resection.step(&sweep, true, false, 1.0 / 60.0);
  EXPECT_EQ(buried.cut_tetrahedra, 0);
  EXPECT_EQ(cut.resection.stats().removed_m3[static_cast<std::size_t>(TissueRegion::kCapsule)], 0.0);
  const TriangleMesh untouched = cut.tissue.live_surface(true);
  ASSERT_TRUE(validate_closed_surface(untouched));
  EXPECT_EQ(validate_closed_surface(untouched)->components, 1);

  sweep.set(CutBlock::wire_at(0.007, 7), CutBlock::wire_at(-0.002, 7), 0.0008);  // back out through the face at y = 0
  const ResectionStep opened = cut.resection.step(&sweep, true, false, 1.0 / 60.0);
  EXPECT_GT(opened.cut_tetrahedra, 0);
  const TriangleMesh after = cut.tissue.live_surface(true);
  Result<SurfaceReport> report = validate_closed_surface(after);
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->components, 1);
  EXPECT_GT(report->volume_m3, 0.0);
}

}  // namespace
}  // namespace resecto
