// The geometry oracle: a straight stroke of a straight wire through a block removes close to the
// analytic volume the inflated wire sweeps, at two resolutions, with refinement on (and off, reported).
#include <gtest/gtest.h>

#include <limits>

#include <cstdio>

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

/// Cuts a 6 mm wire moving 8 mm across itself, radius 1 mm, through the middle of a block of cubes of
/// `cell_m`, in `steps` collision steps; returns the removed volume over the analytic one.
double stroke_ratio(double cell_m, bool refine, int steps, std::size_t max_marked, std::int64_t* refined) {
  const int cells = static_cast<int>(std::lround(0.016 / cell_m));
  const TetMesh block = block_mesh(cells, cells, cells, cell_m);
  MassSpringTissue tissue(block);
  ResectionConfig config;
  config.refine = refine;
  config.max_refined_per_step = max_marked;
  config.channel_origin = Vec3(-1.0);  // no channel: every boundary face is the outer surface
  Resection resection(tissue, config);
  const double r = 0.001, span = 0.006, travel = 0.008;
  // The wire along x at the block's mid-height, moving along y, sampled at 13 points.
  std::vector<Vec3> from, to;
  SweptVolume sweep(13);
  for (int step = 0; step < steps; ++step) {
    from.clear();
    to.clear();
    for (int i = 0; i <= 12; ++i) {
      const double x = 0.005 + span * i / 12.0;
      from.push_back({x, 0.004 + travel * step / steps, 0.008});
      to.push_back({x, 0.004 + travel * (step + 1) / steps, 0.008});
    }
    sweep.set(from, to, r);
    (void)resection.step(&sweep, true, false, 1.0 / 60.0);
  }
  *refined = resection.stats().refined_tetrahedra;
  const double removed = resection.stats().removed_m3[static_cast<std::size_t>(TissueRegion::kCapsule)];
  return removed / SweptVolume::straight_stroke_volume(span, travel, r);
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

}  // namespace
}  // namespace resecto
