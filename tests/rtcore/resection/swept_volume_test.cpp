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

/// Cuts a 6 mm wire, radius 1 mm, moving across itself right through a 16 mm block of cubes of
/// `cell_m` (from 2 mm before its face to 2 mm past the far one, so the cut opens from the surface as
/// the loop's does), in `steps` collision steps; returns the removed volume over the analytic one.
double stroke_ratio(double cell_m, bool refine, int steps, std::size_t max_marked, std::int64_t* refined) {
  const int cells = static_cast<int>(std::lround(0.016 / cell_m));
  const TetMesh block = block_mesh(cells, cells, cells, cell_m);
  MassSpringTissue tissue(block);
  ResectionConfig config;
  config.refine = refine;
  config.max_refined_per_step = max_marked;
  config.channel_origin = Vec3(-1.0);  // no channel: every boundary face is the outer surface
  Resection resection(tissue, config);
  const double r = 0.001, span = 0.006, side = 0.016, start = -0.002, travel = side + 0.004;
  // The wire along x at the block's mid-height, moving along y, sampled at 13 points.
  std::vector<Vec3> from, to;
  SweptVolume sweep(13);
  for (int step = 0; step < steps; ++step) {
    from.clear();
    to.clear();
    for (int i = 0; i <= 12; ++i) {
      const double x = 0.005 + span * i / 12.0;
      from.push_back({x, start + travel * step / steps, 0.008});
      to.push_back({x, start + travel * (step + 1) / steps, 0.008});
    }
    sweep.set(from, to, r);
    (void)resection.step(&sweep, true, false, 1.0 / 60.0);
  }
  *refined = resection.stats().refined_tetrahedra;
  const double removed = resection.stats().removed_m3[static_cast<std::size_t>(TissueRegion::kCapsule)];
  // Inside the block the sweep is the slab and the half-cylinders along the wire's two ends, over
  // the block's whole depth: the rounded ends of the stroke lie outside it.
  const double inside = 2.0 * r * span * side + std::numbers::pi * r * r * side;
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
  const double cell = 0.001;
  const TetMesh block = block_mesh(16, 16, 16, cell);
  MassSpringTissue tissue(block);
  ResectionConfig config;
  config.channel_origin = Vec3(-1.0);  // no channel: every boundary face is the outer surface
  Resection resection(tissue, config);
  SweptVolume sweep(7);
  const auto wire_at = [](double y) {
    std::vector<Vec3> wire;
    for (int i = 0; i <= 6; ++i) wire.push_back({0.005 + 0.006 * i / 6.0, y, 0.008});
    return wire;
  };
  sweep.set(wire_at(0.005), wire_at(0.007), 0.0008);
  const ResectionStep buried = resection.step(&sweep, true, false, 1.0 / 60.0);
  EXPECT_EQ(buried.cut_tetrahedra, 0);
  EXPECT_EQ(resection.stats().removed_m3[static_cast<std::size_t>(TissueRegion::kCapsule)], 0.0);
  const TriangleMesh untouched = tissue.live_surface(true);
  ASSERT_TRUE(validate_closed_surface(untouched));
  EXPECT_EQ(validate_closed_surface(untouched)->components, 1);

  sweep.set(wire_at(0.007), wire_at(-0.002), 0.0008);  // back out through the face at y = 0
  const ResectionStep opened = resection.step(&sweep, true, false, 1.0 / 60.0);
  EXPECT_GT(opened.cut_tetrahedra, 0);
  const TriangleMesh cut = tissue.live_surface(true);
  Result<SurfaceReport> report = validate_closed_surface(cut);
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->components, 1);
  EXPECT_GT(report->volume_m3, 0.0);
}

}  // namespace
}  // namespace resecto
