// The deformable gland: stability at the corners of the parameter ranges, physical sanity of the
// indentation (force grows with stiffness and depth, return to rest, rest is an equilibrium),
// determinism of the state hash, parameter validation, and the spring network's invariants.
#include <gtest/gtest.h>

#include <cmath>

#include "rtcore/base/units.h"
#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/indentation.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

TEST(SpringNetwork, SharesTheVolumeAndAnchorsOnlyTheOuterSurface) {
  const ProstateTissueModel& model = tissue_model(1296);
  const SpringNetwork net = build_spring_network(model.mesh);
  double volume = 0.0, node_volume = 0.0, shares = 0.0;
  for (std::size_t t = 0; t < model.mesh.tetrahedron_count(); ++t) volume += tetrahedron_volume(model.mesh, t);
  for (double v : net.node_volume_m3) node_volume += v;
  for (double v : net.volume_share_m3) shares += v;
  EXPECT_NEAR(node_volume / volume, 1.0, 1e-12);
  EXPECT_NEAR(shares / volume, 1.0, 1e-12);
  // Euler for a tetrahedral mesh: every edge once, sorted, no self-loops.
  for (std::size_t s = 0; s < net.spring_count(); ++s) {
    ASSERT_LT(net.spring_nodes[2 * s], net.spring_nodes[2 * s + 1]);
    if (s > 0) {
      const auto prev = std::make_pair(net.spring_nodes[2 * s - 2], net.spring_nodes[2 * s - 1]);
      ASSERT_LT(prev, std::make_pair(net.spring_nodes[2 * s], net.spring_nodes[2 * s + 1]));
    }
    ASSERT_GT(net.rest_length_m[s], 0.0);
  }
  // Anchors lie on the outer surface; on the channel wall (radius at most 4.6 mm) only at the rims
  // of its openings, where the capsule reaches the lumen, never along the lobes.
  ASSERT_FALSE(net.anchor_nodes.empty());
  double anchor_area = 0.0;
  for (std::size_t a = 0; a < net.anchor_nodes.size(); ++a) {
    const Vec3& p = model.mesh.positions[net.anchor_nodes[a]];
    if (std::hypot(p.x, p.y) < model.anatomy.shape.channel_radius_m + 0.0005) {
      EXPECT_TRUE(p.z < 0.006 || p.z > model.anatomy.shape.length_m - 0.006) << "anchor node " << net.anchor_nodes[a] << " at z " << p.z;
    }
    anchor_area += net.anchor_area_m2[a];
  }
  EXPECT_GT(anchor_area, 20e-4);  // most of the ~60 cm^2 outer surface
  EXPECT_LT(anchor_area, 100e-4);
}

TEST(TissueParameters, RefusesUnknownKeysAndOutOfRangeValuesNamingThem) {
  TissueParameters p;
  EXPECT_DOUBLE_EQ(p.get(TissueParameter::kStiffness), 40.0);
  Status bad_key = p.set_from_assignment("stifness=50");
  ASSERT_FALSE(bad_key);
  EXPECT_NE(bad_key.error().find("unknown parameter 'stifness'"), std::string::npos) << bad_key.error();
  Status bad_value = p.set_from_assignment("stiffness=900");
  ASSERT_FALSE(bad_value);
  EXPECT_NE(bad_value.error().find("out of range [1, 500] kPa"), std::string::npos) << bad_value.error();
  EXPECT_FALSE(p.set_from_assignment("stiffness=abc"));
  EXPECT_FALSE(p.set_from_assignment("stiffness"));
  EXPECT_FALSE(p.set_from_assignment("stiffness=nan"));
  // Audit 6, D: a leading '+' was refused here while `--seconds +2` and a procedure's "+2.0" were read.
  ASSERT_TRUE(p.set_from_assignment("stiffness=+41"));
  EXPECT_DOUBLE_EQ(p.get(TissueParameter::kStiffness), 41.0);
  EXPECT_EQ(p.set_from_assignment("stiffness=4O").error(), "--set stiffness=4O: '4O' is not a number");
  EXPECT_EQ(p.set_from_assignment("stiffness=inf").error(), "--set stiffness=inf: 'inf' is not a finite number");
  EXPECT_FALSE(p.set_from_assignment("stiffness=++40"));
  ASSERT_TRUE(p.set_from_assignment("stiffness=80"));
  EXPECT_DOUBLE_EQ(p.si(TissueParameter::kStiffness), 80e3);
  for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
    EXPECT_LE(spec.min_value, spec.default_value) << spec.key;
    EXPECT_LE(spec.default_value, spec.max_value) << spec.key;
    EXPECT_EQ(find_tissue_parameter(spec.key), spec.id);
  }
}

TEST(MassSpringTissue, RestStateIsAnEquilibrium) {
  MassSpringTissue tissue(tissue_model(1296).mesh);
  const std::uint64_t rest_hash = tissue.state_hash();
  for (int tick = 0; tick < 9600; ++tick) {  // 10 s at 960 Hz, no tool
    if (tick % 16 == 0) tissue.collision_step();
    (void)tissue.physics_step(1.0 / 960.0);
  }
  EXPECT_EQ(tissue.max_displacement_m(), 0.0);
  EXPECT_EQ(tissue.kinetic_energy_j(), 0.0);
  EXPECT_EQ(tissue.state_hash(), rest_hash);
}

TEST(MassSpringTissue, LumpedMassIsDensityTimesVolume) {
  const ProstateTissueModel& model = tissue_model(1296);
  TissueParameters p;
  ASSERT_TRUE(p.set(TissueParameter::kDensity, 1.5));
  MassSpringTissue tissue(model.mesh, p);
  double volume = 0.0;
  for (std::size_t t = 0; t < model.mesh.tetrahedron_count(); ++t) volume += tetrahedron_volume(model.mesh, t);
  EXPECT_NEAR(tissue.total_mass_kg(), 1500.0 * volume, 1e-9);
  tissue.apply({0, TissueParameter::kDensity, 1.0});
  EXPECT_NEAR(tissue.total_mass_kg(), 1000.0 * volume, 1e-9);
}

/// A short protocol: 5 mm in over 0.5 s, hold 0.25 s, out over 0.25 s, relax.
IndentationOptions quick_protocol(double relax_s = 0.5) {
  IndentationOptions o;
  o.press_s = 0.5;
  o.hold_s = 0.25;
  o.withdraw_s = 0.25;
  o.relax_s = relax_s;
  return o;
}

TEST(Indentation, ForceGrowsWithStiffnessAndDepth) {
  const ProstateTissueModel& model = tissue_model(1296);
  auto peak = [&](double stiffness_kpa, double depth_mm) {
    IndentationOptions o = quick_protocol(0.0);
    o.depth_m = units::mm_to_m(depth_mm);
    EXPECT_TRUE(o.parameters.set(TissueParameter::kStiffness, stiffness_kpa));
    const IndentationResult r = run_indentation(model, o);
    EXPECT_TRUE(r.finite);
    return r.peak_force_n;
  };
  const double base = peak(40.0, 5.0);
  const double stiffer = peak(80.0, 5.0);
  const double shallower = peak(40.0, 2.5);
  EXPECT_GT(base, 0.05) << "a 5 mm indentation of 40 kPa tissue pushes back";
  EXPECT_GT(stiffer, 1.4 * base) << "doubling the stiffness raises the force substantially";
  EXPECT_GT(base, 1.4 * shallower) << "twice as deep, substantially more force";
}

TEST(Indentation, ReturnsToRestAfterWithdrawal) {
  // Documented time: every node back within 0.1 mm of rest within 1.5 s of the loop clearing.
  const IndentationResult r = run_indentation(tissue_model(1296), quick_protocol(1.5));
  EXPECT_TRUE(r.finite);
  EXPECT_GT(r.max_displacement_m, 0.002);
  EXPECT_LT(r.residual_m, 1e-4);
  EXPECT_GE(r.settle_time_s, 0.0);
  EXPECT_LT(r.settle_time_s, 1.5);
}

TEST(Indentation, SameRunTwiceGivesTheSameHashAtEveryCollisionStep) {
  auto hashes = [] {
    std::vector<std::uint64_t> out;
    IndentationOptions o = quick_protocol(0.1);
    o.on_collision_step = [&](std::int64_t, std::uint64_t hash) { out.push_back(hash); };
    (void)run_indentation(tissue_model(1296), o);
    return out;
  };
  const std::vector<std::uint64_t> a = hashes(), b = hashes();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 60u);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "collision step " << i;
  EXPECT_NE(a.front(), a[a.size() / 2]) << "the state moved";
}

}  // namespace
}  // namespace resecto

namespace resecto {
namespace {

/// The stability sweep: the harshest corners of the ranges, coarsest and finest affordable meshes,
/// the loop pressed 5 mm into the lobe and withdrawn.
struct Corner {
  const char* name;
  double stiffness, spring_damping, viscous, density, anchor, penalty_k, penalty_c;
};
const Corner kCorners[] = {
    {"stiffest-undamped-light", 500, 0, 0, 0.5, 100, 0.2, 0},
    {"stiffest-most-damped-light", 500, 5000, 2000, 0.5, 100, 10, 10},
    {"soft-most-damped-stiff-contact", 1, 5000, 2000, 0.5, 0.01, 10, 10},
    // These two diverged while the step's inertia D followed the motion (parametric pumping through
    // the springs' geometric term and the contacts); a rise of D now keeps the momentum.
    {"stiffest-undamped-stiff-contact", 500, 0, 0, 0.5, 100, 10, 0},
    {"softest-undamped-heavy", 1, 0, 0, 2.0, 0.01, 0.01, 0},
    {"stiffest-undamped-mid-contact", 500, 0, 0, 0.5, 100, 2, 0},
};

class StabilitySweep : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(StabilitySweep, StaysFiniteBoundedAndInTheScene) {
  const auto [triangles, corner_index] = GetParam();
  const Corner& c = kCorners[corner_index];
  IndentationOptions o;
  o.press_s = 0.25, o.hold_s = 0.1, o.withdraw_s = 0.25, o.relax_s = 0.1;
  TissueParameters& p = o.parameters;
  ASSERT_TRUE(p.set(TissueParameter::kStiffness, c.stiffness) && p.set(TissueParameter::kSpringDamping, c.spring_damping) &&
              p.set(TissueParameter::kViscousDamping, c.viscous) && p.set(TissueParameter::kDensity, c.density) &&
              p.set(TissueParameter::kAnchorStiffness, c.anchor) && p.set(TissueParameter::kPenaltyStiffness, c.penalty_k) &&
              p.set(TissueParameter::kPenaltyDamping, c.penalty_c));
  const IndentationResult r = run_indentation(tissue_model(triangles), o);
  EXPECT_TRUE(r.finite) << c.name << ": first non-finite node " << r.faults.first_non_finite_node;
  // The loop moves at 20 mm/s; 45 g moving as a whole at ten times that would hold 1e-3 J.
  EXPECT_LT(r.max_kinetic_energy_j, 1e-3) << c.name;
  EXPECT_LT(r.max_escape_m, 0.010) << c.name << ": a node left the scene";
  EXPECT_LT(r.max_displacement_m, 0.015) << c.name;
  EXPECT_GT(r.max_displacement_m, 0.001) << c.name << ": the loop pressed in";
}

INSTANTIATE_TEST_SUITE_P(Corners, StabilitySweep, ::testing::Combine(::testing::Values(1296, 8640), ::testing::Range(0, 3)));
INSTANTIATE_TEST_SUITE_P(UndampedCorners, StabilitySweep, ::testing::Combine(::testing::Values(1296, 8640), ::testing::Values(3, 4, 5)));

}  // namespace
}  // namespace resecto
