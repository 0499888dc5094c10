// The procedural prostate: valid closed genus-1 surfaces at every size the paper used and far beyond,
// the triangle counts asked for, a plausible 45 g gland, and bit-identical output for equal arguments.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include <nlohmann/json.hpp>

#include "rtcore/anatomy/prostate.h"
#include "rtcore/base/units.h"
#include "rtcore/mesh/mesh_validation.h"

namespace resecto {
namespace {

class PaperSizes : public ::testing::TestWithParam<int> {};

TEST_P(PaperSizes, IsAValidClosedGenusOneSurfaceWithinTwoPercent) {
  const int target = GetParam();
  const ProstateModel model = generate_prostate(target);
  const double count = static_cast<double>(model.surface.triangle_count());
  EXPECT_LE(std::abs(count - target) / target, 0.02) << count << " triangles for " << target;
  Result<SurfaceReport> report = validate_closed_surface(model.surface);
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->components, 1);
  EXPECT_EQ(report->genus, 1);
  EXPECT_GT(report->volume_m3, 0.0);
  EXPECT_GT(report->min_angle_deg, 5.0);
}

INSTANTIATE_TEST_SUITE_P(Figure13, PaperSizes,
                         ::testing::Values(1296, 1482, 1560, 2069, 2816, 3128, 3744, 5292, 5670, 7260, 8640, 34560, 138240));

TEST(Prostate, DefaultGlandWeighsAbout45Grams) {
  const ProstateModel model = generate_prostate(8640);
  const double grams = signed_volume(model.surface) * model.shape.tissue_density_kg_m3 * units::kGramsPerKilogram;
  EXPECT_NEAR(grams, 45.0, 2.0);
  const Aabb box = bounding_box(model.surface);
  EXPECT_NEAR(box.size().x, model.shape.width_m, 0.002);
  EXPECT_NEAR(box.size().z, model.shape.length_m, 1e-6);
  EXPECT_LT(box.size().y, model.shape.height_m + 1e-3);
}

TEST(Prostate, SameArgumentsGiveBitIdenticalMeshes) {
  const ProstateModel a = generate_prostate(5292);
  const ProstateModel b = generate_prostate(5292);
  ASSERT_EQ(a.surface.positions.size(), b.surface.positions.size());
  EXPECT_EQ(0, std::memcmp(a.surface.positions.data(), b.surface.positions.data(), a.surface.positions.size() * sizeof(Vec3)));
  EXPECT_EQ(a.surface.triangles, b.surface.triangles);
  EXPECT_EQ(landmarks_to_json(a), landmarks_to_json(b));
}

TEST(Prostate, ChannelIsOpenFromApexToBladderNeckAndNarrowedByTheLobes) {
  const ProstateShape shape;
  // The lumen stays open everywhere, and the lobes narrow it where they should.
  for (double zn = 0.0; zn <= 1.0; zn += 0.01) {
    for (double theta = 0.0; theta < 2.0 * std::numbers::pi; theta += 0.05) {
      const double r = channel_radius_at(shape, zn * shape.length_m, theta);
      EXPECT_GT(r, 0.0015);
      EXPECT_LE(r, shape.channel_radius_m);
    }
  }
  EXPECT_LT(channel_radius_at(shape, 0.55 * shape.length_m, 0.0), shape.channel_radius_m - 0.0015);
  EXPECT_LT(channel_radius_at(shape, 0.55 * shape.length_m, std::numbers::pi), shape.channel_radius_m - 0.0015);
  EXPECT_LT(channel_radius_at(shape, 0.90 * shape.length_m, -0.5 * std::numbers::pi), shape.channel_radius_m - 0.002);
  EXPECT_NEAR(channel_radius_at(shape, 0.55 * shape.length_m, 0.5 * std::numbers::pi), shape.channel_radius_m, 2e-4);

  // No surface vertex lies inside the lumen: a straight path along the axis stays clear.
  const ProstateModel model = generate_prostate(8640);
  for (const Vec3& p : model.surface.positions) {
    const double r = std::hypot(p.x, p.y);
    if (p.z > 1e-3 && p.z < shape.length_m - 1e-3) {
      EXPECT_GE(r, channel_radius_at(shape, p.z, std::atan2(p.y, p.x)) - 1e-9);
    }
  }
}

TEST(Prostate, LandmarksLieWhereAnatomySaysAndAreWrittenInMillimetres) {
  const ProstateModel model = generate_prostate(3744);
  auto find = [&](const std::string& name) {
    for (const Landmark& l : model.landmarks) {
      if (l.name == name) return l.position;
    }
    ADD_FAILURE() << "missing landmark " << name;
    return Vec3(0.0);
  };
  EXPECT_NEAR(find("bladder_neck").z, model.shape.length_m, 1e-9);
  EXPECT_LT(find("verumontanum").y, 0.0);  // posterior wall
  EXPECT_LT(find("verumontanum").z, 0.35 * model.shape.length_m);
  EXPECT_LT(find("external_sphincter").z, 0.0);  // distal to the apex
  EXPECT_GT(find("lateral_lobe_left").x, 0.0);   // x is the patient's left
  EXPECT_LT(find("lateral_lobe_right").x, 0.0);
  EXPECT_GT(find("median_lobe").z, find("verumontanum").z);

  const auto doc = nlohmann::json::parse(landmarks_to_json(model));
  EXPECT_EQ(doc.at("units"), "mm");
  EXPECT_NEAR(doc.at("channel_axis").at("bladder_neck").at(2).get<double>(), units::m_to_mm(model.shape.length_m), 1e-9);
  EXPECT_EQ(doc.at("landmarks").size(), model.landmarks.size());
}

}  // namespace
}  // namespace resecto
