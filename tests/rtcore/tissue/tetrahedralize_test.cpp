// TetGen's volumetric model of the procedural gland: volume kept, boundary kept face for face,
// capsule and adenoma labelled, failures turned into errors, files that round-trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <unistd.h>

#include "rtcore/anatomy/prostate.h"
#include "rtcore/base/units.h"
#include "rtcore/tissue/tetrahedralize.h"

namespace resecto {
namespace {

TetrahedralizeOptions prostate_options(const ProstateModel& model) {
  TetrahedralizeOptions options;
  options.capsule_thickness_m = model.shape.capsule_thickness_m;
  options.channel_axis = {{0.0, 0.0, 0.0}, {0.0, 0.0, model.shape.length_m}};
  return options;
}

std::vector<std::array<std::uint32_t, 3>> sorted_faces(const TriangleMesh& mesh) {
  std::vector<std::array<std::uint32_t, 3>> faces;
  for (Triangle t : mesh.triangles) {
    // Rotate so the smallest index leads: keeps the winding, forgets the starting corner.
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    faces.push_back(t);
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

class TetraSizes : public ::testing::TestWithParam<int> {};

TEST_P(TetraSizes, KeepsVolumeAndBoundaryAndLabelsBothRegions) {
  const ProstateModel model = generate_prostate(GetParam());
  Result<TetMesh> tetra = tetrahedralize(model.surface, prostate_options(model));
  ASSERT_TRUE(tetra) << tetra.error();
  const TetMeshStats stats = compute_stats(*tetra);
  const double surface_volume = signed_volume(model.surface);
  EXPECT_NEAR(stats.volume_m3 / surface_volume, 1.0, 0.01);
  for (std::size_t t = 0; t < tetra->tetrahedron_count(); ++t) ASSERT_GT(tetrahedron_volume(*tetra, t), 0.0) << "tetrahedron " << t;
  EXPECT_GT(stats.min_dihedral_deg, 1.0);

  // The tissue's surface is exactly the input surface, on the same node indices, wound the same way.
  EXPECT_EQ(sorted_faces(boundary_surface(*tetra)), sorted_faces(model.surface));
  for (std::size_t v = 0; v < model.surface.vertex_count(); ++v) ASSERT_EQ(tetra->positions[v], model.surface.positions[v]);

  // A shell a few millimetres thick is a large minority of a 45 g gland; the adenoma is the rest.
  EXPECT_GT(stats.capsule_volume_m3, 0.15 * stats.volume_m3);
  EXPECT_LT(stats.capsule_volume_m3, 0.5 * stats.volume_m3);
  // Tissue next to the channel is adenoma: the lumen is not capsule.
  for (std::size_t t = 0; t < tetra->tetrahedron_count(); ++t) {
    const Tetrahedron& tet = tetra->tetrahedra[t];
    const Vec3 c = 0.25 * (tetra->positions[tet[0]] + tetra->positions[tet[1]] + tetra->positions[tet[2]] + tetra->positions[tet[3]]);
    if (c.z > 0.01 && c.z < 0.03 && std::hypot(c.x, c.y) < model.shape.channel_radius_m + 0.001) {
      EXPECT_EQ(tetra->regions[t], TissueRegion::kAdenoma) << "tetrahedron " << t << " by the channel";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Prostate, TetraSizes, ::testing::Values(1296, 8640));

TEST(Tetrahedralize, IsDeterministic) {
  const ProstateModel model = generate_prostate(2069);
  Result<TetMesh> a = tetrahedralize(model.surface, prostate_options(model));
  Result<TetMesh> b = tetrahedralize(model.surface, prostate_options(model));
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->positions, b->positions);
  EXPECT_EQ(a->tetrahedra, b->tetrahedra);
  EXPECT_EQ(a->regions, b->regions);
}

TEST(Tetrahedralize, VolumeConstraintRefinesTheMesh) {
  const ProstateModel model = generate_prostate(1296);
  TetrahedralizeOptions coarse = prostate_options(model), fine = coarse;
  fine.max_volume_m3 = 2e-9;  // 2 mm^3
  Result<TetMesh> a = tetrahedralize(model.surface, coarse);
  Result<TetMesh> b = tetrahedralize(model.surface, fine);
  ASSERT_TRUE(a && b);
  EXPECT_GT(b->tetrahedron_count(), 2 * a->tetrahedron_count());
  // With the boundary kept (-Y) TetGen refuses Steiner points that would encroach on the surface, so
  // the bound is a target, not a guarantee: most tetrahedra meet it and the largest shrink.
  std::size_t within = 0;
  double largest_coarse = 0.0, largest_fine = 0.0;
  for (std::size_t t = 0; t < a->tetrahedron_count(); ++t) largest_coarse = std::max(largest_coarse, tetrahedron_volume(*a, t));
  for (std::size_t t = 0; t < b->tetrahedron_count(); ++t) {
    const double volume = tetrahedron_volume(*b, t);
    largest_fine = std::max(largest_fine, volume);
    within += volume <= 2e-9 * 1.0001 ? 1 : 0;
  }
  EXPECT_GT(within, 8 * b->tetrahedron_count() / 10) << within << " of " << b->tetrahedron_count();
  EXPECT_LT(largest_fine, 0.5 * largest_coarse);
}

TEST(Tetrahedralize, SelfIntersectingSurfaceIsAnErrorNotACrash) {
  // Two overlapping closed tetrahedra: TetGen throws in library mode; we must turn it into an error.
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {0.002, 0, 0}, {0, 0.002, 0}, {0, 0, 0.002},
                    {0.0002, 0.0002, 0.0002}, {0.003, 0.0002, 0.0002}, {0.0002, 0.003, 0.0002}, {0.0002, 0.0002, 0.003}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {4, 6, 5}, {4, 5, 7}, {4, 7, 6}, {5, 6, 7}};
  Result<TetMesh> tetra = tetrahedralize(mesh);
  ASSERT_FALSE(tetra);
  EXPECT_NE(tetra.error().find("self-intersection"), std::string::npos) << tetra.error();
}

/// A closed outward tetrahedron with `side_m` legs at the origin, and optionally one vertex no face
/// uses, at `unused` (placed first, so the used ones are renumbered).
TriangleMesh corner_tetrahedron(double side_m, std::optional<Vec3> unused = std::nullopt) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {side_m, 0, 0}, {0, side_m, 0}, {0, 0, side_m}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  if (unused) {
    mesh.positions.insert(mesh.positions.begin(), *unused);
    for (Triangle& t : mesh.triangles) {
      for (std::uint32_t& v : t) ++v;
    }
  }
  return mesh;
}

TEST(Tetrahedralize, UnusedVerticesNeverReachTetGen) {
  // Outside the hull it crashed TetGen (SIGSEGV in its memory pool); inside it became a node with
  // slivers around it. Either way the tissue is the tetrahedron alone, on its 4 corners in order.
  for (const Vec3 unused : {Vec3(0.05, 0.05, 0.05), Vec3(0.001, 0.001, 0.001), Vec3(0.005, 0.005, 0.0)}) {
    const TriangleMesh surface = corner_tetrahedron(0.01, unused);
    Result<TetMesh> tetra = tetrahedralize(surface);
    ASSERT_TRUE(tetra) << tetra.error();
    EXPECT_EQ(tetra->tetrahedron_count(), 1u);
    ASSERT_EQ(tetra->node_count(), 4u);
    for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(tetra->positions[v], surface.positions[v + 1]);
  }
}

TEST(Tetrahedralize, CapsuleLabellingIsBoundedByTheFaceCountNotTheShell) {
  // A 0 mm shell once meant 1 um cells (16.8 GB for a 10 mm tetrahedron), and 2.5 mm cells over a
  // 10 m tetrahedron as much: the grid now grows its cells, and the labels stay exact.
  TetrahedralizeOptions thin;
  thin.capsule_thickness_m = 0.0;
  Result<TetMesh> small = tetrahedralize(corner_tetrahedron(0.01), thin);
  ASSERT_TRUE(small) << small.error();
  EXPECT_EQ(small->regions, std::vector<TissueRegion>{TissueRegion::kAdenoma});
  Result<TetMesh> large = tetrahedralize(corner_tetrahedron(10.0));
  ASSERT_TRUE(large) << large.error();
  EXPECT_EQ(large->regions, std::vector<TissueRegion>{TissueRegion::kAdenoma});  // centroid 1.4 m in
  TetrahedralizeOptions thick;
  thick.capsule_thickness_m = 2.0;  // beyond the centroid's 1.44 m from the nearest face
  Result<TetMesh> shell = tetrahedralize(corner_tetrahedron(10.0), thick);
  ASSERT_TRUE(shell) << shell.error();
  EXPECT_EQ(shell->regions, std::vector<TissueRegion>{TissueRegion::kCapsule});
}

TEST(Tetrahedralize, UnreachableQualityIsAnErrorAtTheSteinerBudget) {
  // Bounds this tight never terminate in TetGen on a smooth surface; the budget stops it and says so.
  const ProstateModel model = generate_prostate(1296);
  TetrahedralizeOptions options = prostate_options(model);
  options.min_dihedral_deg = 30.0;
  options.max_steiner_points = 50;
  Result<TetMesh> tetra = tetrahedralize(model.surface, options);
  ASSERT_FALSE(tetra);
  EXPECT_NE(tetra.error().find("limit of 50 points"), std::string::npos) << tetra.error();
  EXPECT_NE(tetra.error().find("dihedral angles of 30 deg (reached"), std::string::npos) << tetra.error();
}

TEST(Tetrahedralize, AVolumeBoundAskingForMillionsOfTetrahedraIsRefusedAtOnce) {
  // --max-volume 0.001 mm^3 in a 42 ml gland asks for 42 million tetrahedra: TetGen took 3 GB in a
  // minute and went on. Refused before TetGen starts, naming a bound that would do.
  const ProstateModel model = generate_prostate(1296);
  TetrahedralizeOptions options = prostate_options(model);
  options.max_volume_m3 = 0.001 * 1e-9;
  const auto start = std::chrono::steady_clock::now();
  Result<TetMesh> tetra = tetrahedralize(model.surface, options);
  ASSERT_FALSE(tetra);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5)) << "TetGen ran";
  EXPECT_NE(tetra.error().find("maximum tetrahedron volume 0.001 mm^3 asks for about"), std::string::npos) << tetra.error();
  EXPECT_NE(tetra.error().find("mm^3 or more"), std::string::npos) << tetra.error();
}

TEST(Tetrahedralize, RejectsImpossibleOptions) {
  const ProstateModel model = generate_prostate(1296);
  TetrahedralizeOptions options;
  options.max_radius_edge_ratio = 0.5;
  Result<TetMesh> tetra = tetrahedralize(model.surface, options);
  ASSERT_FALSE(tetra);
  EXPECT_NE(tetra.error().find("radius-edge"), std::string::npos);
}

TEST(TetMeshFiles, VtkRoundTripsAndTruncationNamesTheLine) {
  const ProstateModel model = generate_prostate(1296);
  Result<TetMesh> tetra = tetrahedralize(model.surface, prostate_options(model));
  ASSERT_TRUE(tetra);
  const auto dir = std::filesystem::temp_directory_path() / ("resecto_tetra_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "gland.vtk";
  ASSERT_TRUE(write_vtk(path, *tetra));
  Result<TetMesh> back = read_vtk(path);
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(back->tetrahedra, tetra->tetrahedra);
  EXPECT_EQ(back->regions, tetra->regions);
  for (std::size_t v = 0; v < back->node_count(); ++v) ASSERT_NEAR(glm::length(back->positions[v] - tetra->positions[v]), 0.0, 1e-9);

  // Cut the file in the middle of its cells.
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto cut = dir / "cut.vtk";
  std::ofstream(cut) << text.substr(0, text.find("CELLS") + 200);
  Result<TetMesh> truncated = read_vtk(cut);
  ASSERT_FALSE(truncated);
  EXPECT_NE(truncated.error().find("cut.vtk:"), std::string::npos) << truncated.error();
  EXPECT_NE(truncated.error().find("truncated"), std::string::npos) << truncated.error();
}

}  // namespace
}  // namespace resecto
