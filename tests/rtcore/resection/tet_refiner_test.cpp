// TetRefiner against brute force: each plan is applied to plain vectors the way the resection module
// applies it, and the result is checked face by face (conforming, closed, consistently oriented, no
// hanging node), tetrahedron by tetrahedron (positive, eighths for red) and in sum (volume per region,
// lumped mass, uniform-strain spring energy). Meshes: hand-made ones, a TetGen box, the 1296 gland.
#include "rtcore/resection/tet_refiner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include "rtcore/tissue/springs.h"
#include "rtcore/tissue/tetrahedralize.h"
#include "tests/support/realtime_probe.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

/// A mesh in the flat arrays a simulation holds: slots that die stay in place.
struct PlainMesh {
  std::vector<Vec3> rest;
  std::vector<Tetrahedron> tets;
  std::vector<std::uint8_t> alive;
  std::vector<TissueRegion> regions;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;  ///< every node made by refinement
  /// Whether every boundary edge has exactly two boundary faces; a resected mesh may touch itself
  /// along an edge, and then its boundary is only closed (each directed edge matched by its reverse).
  bool manifold_boundary = true;

  TetMeshView view() const { return {rest, tets, alive, regions}; }
};

double signed_volume(const PlainMesh& m, const Tetrahedron& t) {
  const Vec3& a = m.rest[t[0]];
  return dot(m.rest[t[1]] - a, cross(m.rest[t[2]] - a, m.rest[t[3]] - a)) / 6.0;
}

/// Builds a mesh from corner lists of any orientation, turning each positive.
PlainMesh make_mesh(std::vector<Vec3> positions, std::vector<Tetrahedron> tets, TissueRegion region = TissueRegion::kAdenoma) {
  PlainMesh m;
  m.rest = std::move(positions);
  for (Tetrahedron t : tets) {
    if (signed_volume(m, t) < 0.0) std::swap(t[2], t[3]);
    m.tets.push_back(t);
  }
  m.alive.assign(m.tets.size(), 1);
  m.regions.assign(m.tets.size(), region);
  return m;
}

PlainMesh from_tet_mesh(const TetMesh& mesh) {
  PlainMesh m;
  m.rest = mesh.positions;
  m.tets = mesh.tetrahedra;
  m.regions = mesh.regions;
  m.alive.assign(m.tets.size(), 1);
  return m;
}

/// Applies an edit as a caller would: new nodes appended, children into the removed slots first
/// (reused), the rest appended.
void apply(PlainMesh& m, const RefinementEdit& edit) {
  ASSERT_EQ(edit.first_new_node, m.rest.size());
  for (const auto& parents : edit.new_node_parents) {
    ASSERT_LT(parents[0], edit.first_new_node);
    ASSERT_LT(parents[1], edit.first_new_node);
    m.midpoint[{std::min(parents[0], parents[1]), std::max(parents[0], parents[1])}] = static_cast<std::uint32_t>(m.rest.size());
    m.rest.push_back((m.rest[parents[0]] + m.rest[parents[1]]) * 0.5);
  }
  for (std::uint32_t s : edit.removed_tetrahedra) {
    ASSERT_TRUE(m.alive[s]) << "slot " << s;
    m.alive[s] = 0;
  }
  std::size_t reuse = 0;
  for (std::size_t c = 0; c < edit.added_tetrahedra.size(); ++c) {
    if (reuse < edit.removed_tetrahedra.size()) {
      const std::uint32_t s = edit.removed_tetrahedra[reuse++];
      m.tets[s] = edit.added_tetrahedra[c];
      m.regions[s] = edit.added_regions[c];
      m.alive[s] = 1;
    } else {
      m.tets.push_back(edit.added_tetrahedra[c]);
      m.regions.push_back(edit.added_regions[c]);
      m.alive.push_back(1);
    }
  }
}

/// The live tetrahedra as a TetMesh (all nodes kept), for the spring network and the measures.
TetMesh live_mesh(const PlainMesh& m) {
  TetMesh out;
  out.positions = m.rest;
  for (std::size_t s = 0; s < m.tets.size(); ++s) {
    if (m.alive[s]) {
      out.tetrahedra.push_back(m.tets[s]);
      out.regions.push_back(m.regions[s]);
    }
  }
  return out;
}

struct Totals {
  double adenoma_m3 = 0.0, capsule_m3 = 0.0, boundary_area_m2 = 0.0;
};

/// Brute-force conformity: every face held by one live tetrahedron (boundary) or two with opposite
/// windings; the boundary closed and consistently oriented (each directed edge once, its reverse
/// once); every live tetrahedron positive; no live edge with a used midpoint (a hanging node).
Totals check_conforming(const PlainMesh& m) {
  Totals totals;
  constexpr int kOutward[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::map<std::array<std::uint32_t, 3>, std::vector<std::array<std::uint32_t, 3>>> faces;
  std::vector<std::uint8_t> used(m.rest.size(), 0);
  for (std::size_t s = 0; s < m.tets.size(); ++s) {
    if (!m.alive[s]) continue;
    const Tetrahedron& t = m.tets[s];
    const double v = signed_volume(m, t);
    EXPECT_GT(v, 0.0) << "slot " << s << " is not positively oriented";
    (m.regions[s] == TissueRegion::kAdenoma ? totals.adenoma_m3 : totals.capsule_m3) += v;
    for (std::uint32_t n : t) used[n] = 1;
    for (const auto& f : kOutward) {
      std::array<std::uint32_t, 3> wound{t[f[0]], t[f[1]], t[f[2]]};
      std::array<std::uint32_t, 3> key = wound;
      std::sort(key.begin(), key.end());
      faces[key].push_back(wound);
    }
  }
  auto same_winding = [](std::array<std::uint32_t, 3> a, std::array<std::uint32_t, 3> b) {
    std::rotate(a.begin(), std::min_element(a.begin(), a.end()), a.end());
    std::rotate(b.begin(), std::min_element(b.begin(), b.end()), b.end());
    return a == b;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& [key, windings] : faces) {
    EXPECT_LE(windings.size(), 2u) << "face " << key[0] << " " << key[1] << " " << key[2] << " held by more than two";
    if (windings.size() == 2) {
      EXPECT_FALSE(same_winding(windings[0], windings[1])) << "face " << key[0] << " " << key[1] << " " << key[2] << " wound alike";
    } else {
      const auto& w = windings[0];
      totals.boundary_area_m2 += 0.5 * length(cross(m.rest[w[1]] - m.rest[w[0]], m.rest[w[2]] - m.rest[w[0]]));
      for (int k = 0; k < 3; ++k) ++directed[{w[k], w[(k + 1) % 3]}];
    }
  }
  for (const auto& [edge, count] : directed) {
    if (m.manifold_boundary) {
      EXPECT_EQ(count, 1) << "boundary edge " << edge.first << "->" << edge.second;
    }
    const auto reverse = directed.find({edge.second, edge.first});
    EXPECT_TRUE(reverse != directed.end() && reverse->second == count) << "boundary edge " << edge.first << "->" << edge.second << " unmatched";
  }
  constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (std::size_t s = 0; s < m.tets.size(); ++s) {
    if (!m.alive[s]) continue;
    for (const auto& e : kEdges) {
      const std::uint32_t a = std::min(m.tets[s][e[0]], m.tets[s][e[1]]), b = std::max(m.tets[s][e[0]], m.tets[s][e[1]]);
      const auto it = m.midpoint.find({a, b});
      EXPECT_FALSE(it != m.midpoint.end() && used[it->second]) << "hanging node " << it->second << " on edge " << a << "-" << b << " of slot " << s;
    }
  }
  return totals;
}

/// Per-edit checks: children positive, conserving each parent's volume; red parents in exact eighths;
/// the marked ones among the red; closure parents in 2-4 children; counts as reported.
void check_edit(const PlainMesh& before, const RefinementEdit& edit, std::span<const std::uint32_t> marked) {
  ASSERT_EQ(edit.added_tetrahedra.size(), edit.added_regions.size());
  ASSERT_EQ(edit.added_tetrahedra.size(), edit.added_parent.size());
  EXPECT_TRUE(std::is_sorted(edit.removed_tetrahedra.begin(), edit.removed_tetrahedra.end()));
  EXPECT_TRUE(std::adjacent_find(edit.removed_tetrahedra.begin(), edit.removed_tetrahedra.end()) == edit.removed_tetrahedra.end());
  PlainMesh after = before;  // positions of the new nodes, for the children's volumes
  for (const auto& p : edit.new_node_parents) after.rest.push_back((before.rest[p[0]] + before.rest[p[1]]) * 0.5);
  std::map<std::uint32_t, std::vector<double>> children;
  for (std::size_t c = 0; c < edit.added_tetrahedra.size(); ++c) {
    const std::uint32_t parent = edit.added_parent[c];
    EXPECT_EQ(edit.added_regions[c], before.regions[parent]);
    const double v = signed_volume(after, edit.added_tetrahedra[c]);
    EXPECT_GT(v, 0.0) << "child " << c << " of slot " << parent;
    children[parent].push_back(v);
  }
  ASSERT_EQ(children.size(), edit.removed_tetrahedra.size());
  int red = 0, closure = 0;
  for (const auto& [parent, volumes] : children) {
    EXPECT_TRUE(std::binary_search(edit.removed_tetrahedra.begin(), edit.removed_tetrahedra.end(), parent));
    const double parent_volume = signed_volume(before, before.tets[parent]);
    double sum = 0.0;
    for (double v : volumes) sum += v;
    EXPECT_NEAR(sum / parent_volume, 1.0, 1e-12) << "slot " << parent;
    if (volumes.size() == 8) {
      ++red;
      for (double v : volumes) EXPECT_NEAR(v / parent_volume, 0.125, 1e-12) << "slot " << parent;
    } else {
      ++closure;
      EXPECT_GE(volumes.size(), 2u);
      EXPECT_LE(volumes.size(), 4u);
    }
  }
  EXPECT_EQ(red, edit.red_tetrahedra);
  EXPECT_EQ(closure, edit.closure_tetrahedra);
  for (std::uint32_t s : marked) {
    if (s < before.tets.size() && before.alive[s]) {
      EXPECT_EQ(children[s].size(), 8u) << "marked slot " << s;
    }
  }
}

/// Plans, checks the edit, applies it and checks the result keeps the volume per region and the
/// boundary's area.
const RefinementEdit& refine_and_check(TetRefiner& refiner, PlainMesh& m, std::span<const std::uint32_t> marked) {
  const Totals before = check_conforming(m);
  const RefinementEdit& edit = refiner.plan(m.view(), marked);
  check_edit(m, edit, marked);
  apply(m, edit);
  const Totals after = check_conforming(m);
  EXPECT_NEAR(after.adenoma_m3, before.adenoma_m3, 1e-12 * (before.adenoma_m3 + before.capsule_m3));
  EXPECT_NEAR(after.capsule_m3, before.capsule_m3, 1e-12 * (before.adenoma_m3 + before.capsule_m3));
  EXPECT_NEAR(after.boundary_area_m2 / before.boundary_area_m2, 1.0, 1e-12);
  return edit;
}

/// The unit cube's corners, corner i at (i & 1, i >> 1 & 1, i >> 2 & 1), scaled to millimetres.
std::vector<Vec3> cube_corners() {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.push_back(0.001 * Vec3(i & 1, i >> 1 & 1, i >> 2 & 1));
  return p;
}

/// Five tetrahedra: four corners cut off around the central regular one (0, 3, 5, 6).
PlainMesh cube_of_five() {
  return make_mesh(cube_corners(), {{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}});
}

/// Six tetrahedra around the diagonal 0-7 (Kuhn's triangulation).
PlainMesh cube_of_six() {
  return make_mesh(cube_corners(), {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}});
}

/// A 2 cm box tetrahedralized by TetGen: several hundred tetrahedra of realistic shape. TetGen keeps
/// the boundary faces (-Y), so each side is a grid of 4 mm squares.
PlainMesh tetgen_box() {
  constexpr int kCells = 5;
  constexpr double kSide = 0.02;
  TriangleMesh box;
  std::map<std::array<int, 3>, std::uint32_t> vertex;
  auto at = [&](std::array<int, 3> g) {
    auto [it, added] = vertex.try_emplace(g, static_cast<std::uint32_t>(box.positions.size()));
    if (added) box.positions.push_back(Vec3(g[0], g[1], g[2]) * (kSide / kCells));
    return it->second;
  };
  // Side `axis` at `high` (0 or kCells), gridded over the other two axes (u, v), wound outward.
  for (int axis = 0; axis < 3; ++axis) {
    for (int high : {0, kCells}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < kCells; ++i) {
        for (int j = 0; j < kCells; ++j) {
          std::array<std::uint32_t, 4> q;
          const int corners[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
          for (int k = 0; k < 4; ++k) {
            std::array<int, 3> g{};
            g[axis] = high, g[u] = corners[k][0], g[v] = corners[k][1];
            q[k] = at(g);
          }
          // (u, v, axis) is right-handed, so u then v turns counter-clockwise seen from +axis.
          if (high) {
            box.triangles.push_back({q[0], q[1], q[2]}), box.triangles.push_back({q[0], q[2], q[3]});
          } else {
            box.triangles.push_back({q[0], q[2], q[1]}), box.triangles.push_back({q[0], q[3], q[2]});
          }
        }
      }
    }
  }
  TetrahedralizeOptions options;
  options.max_volume_m3 = 1e-8;  // 10 mm^3
  Result<TetMesh> mesh = tetrahedralize(box, options);
  EXPECT_TRUE(mesh) << mesh.error();
  PlainMesh m = from_tet_mesh(*mesh);
  EXPECT_GT(m.tets.size(), 800u);
  // Two regions, split by a plane, so the per-region checks mean something.
  for (std::size_t s = 0; s < m.tets.size(); ++s) {
    const Tetrahedron& t = m.tets[s];
    const double x = (m.rest[t[0]].x + m.rest[t[1]].x + m.rest[t[2]].x + m.rest[t[3]].x) / 4.0;
    m.regions[s] = x < 0.01 ? TissueRegion::kCapsule : TissueRegion::kAdenoma;
  }
  return m;
}

std::vector<std::uint32_t> live_slots(const PlainMesh& m) {
  std::vector<std::uint32_t> live;
  for (std::uint32_t s = 0; s < m.tets.size(); ++s) {
    if (m.alive[s]) live.push_back(s);
  }
  return live;
}

/// The `count` live slots whose centroids lie nearest `point`, ascending by distance then slot.
std::vector<std::uint32_t> slots_near(const PlainMesh& m, const Vec3& point, std::size_t count) {
  std::vector<std::pair<double, std::uint32_t>> by_distance;
  for (std::uint32_t s = 0; s < m.tets.size(); ++s) {
    if (!m.alive[s]) continue;
    const Tetrahedron& t = m.tets[s];
    const Vec3 c = (m.rest[t[0]] + m.rest[t[1]] + m.rest[t[2]] + m.rest[t[3]]) * 0.25;
    by_distance.emplace_back(length_squared(c - point), s);
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<std::uint32_t> slots;
  for (std::size_t i = 0; i < count && i < by_distance.size(); ++i) slots.push_back(by_distance[i].second);
  return slots;
}

double min_dihedral_deg(const PlainMesh& m, const Tetrahedron& t) {
  TetMesh one;
  one.positions = {m.rest[t[0]], m.rest[t[1]], m.rest[t[2]], m.rest[t[3]]};
  one.tetrahedra = {{0, 1, 2, 3}};
  return dihedral_angles(one, 0).front() * 180.0 / std::numbers::pi;
}

void expect_same_edit(const RefinementEdit& a, const RefinementEdit& b) {
  EXPECT_EQ(a.first_new_node, b.first_new_node);
  EXPECT_EQ(a.new_node_parents, b.new_node_parents);
  EXPECT_EQ(a.removed_tetrahedra, b.removed_tetrahedra);
  EXPECT_EQ(a.added_tetrahedra, b.added_tetrahedra);
  EXPECT_EQ(a.added_regions, b.added_regions);
  EXPECT_EQ(a.added_parent, b.added_parent);
  EXPECT_EQ(a.red_tetrahedra, b.red_tetrahedra);
  EXPECT_EQ(a.closure_tetrahedra, b.closure_tetrahedra);
}

TEST(TetRefiner, OneTetrahedronSplitsIntoEightEighths) {
  PlainMesh m = make_mesh({{0, 0, 0}, {0.001, 0, 0}, {0, 0.001, 0}, {0, 0, 0.001}}, {{0, 1, 2, 3}});
  TetRefiner refiner(64, 64);
  const std::uint32_t marked[] = {0};
  const RefinementEdit& edit = refine_and_check(refiner, m, marked);
  EXPECT_EQ(edit.new_node_parents.size(), 6u);
  EXPECT_EQ(edit.added_tetrahedra.size(), 8u);
  EXPECT_EQ(edit.red_tetrahedra, 1);
  EXPECT_EQ(edit.closure_tetrahedra, 0);
  // Sorted edges, so the midpoints are numbered in edge order.
  EXPECT_EQ(edit.new_node_parents.front(), (std::array<std::uint32_t, 2>{0, 1}));
  EXPECT_EQ(edit.new_node_parents.back(), (std::array<std::uint32_t, 2>{2, 3}));
}

TEST(TetRefiner, NeighbourAcrossAFaceClosesWithFourChildren) {
  // Two tetrahedra on the face (0, 1, 2): refining one splits that face 1:4, which the other closes
  // by coning it to its apex.
  PlainMesh m = make_mesh({{0, 0, 0}, {0.001, 0, 0}, {0.0003, 0.001, 0}, {0.0004, 0.0003, 0.001}, {0.0004, 0.0003, -0.001}},
                          {{0, 1, 2, 3}, {0, 1, 2, 4}});
  TetRefiner refiner(64, 64);
  const std::uint32_t marked[] = {0};
  const RefinementEdit& edit = refine_and_check(refiner, m, marked);
  EXPECT_EQ(edit.red_tetrahedra, 1);
  EXPECT_EQ(edit.closure_tetrahedra, 1);
  EXPECT_EQ(edit.added_tetrahedra.size(), 12u);
  EXPECT_EQ(edit.new_node_parents.size(), 6u);
}

TEST(TetRefiner, EveryTetrahedronOfBothCubesAsTheMarkedOne) {
  for (PlainMesh (*make)() : {&cube_of_five, &cube_of_six}) {
    const PlainMesh original = make();
    for (std::uint32_t s = 0; s < original.tets.size(); ++s) {
      SCOPED_TRACE(::testing::Message() << original.tets.size() << " tetrahedra, slot " << s << " marked");
      PlainMesh m = original;
      TetRefiner refiner(64, 64);
      const std::uint32_t marked[] = {s};
      refine_and_check(refiner, m, marked);
      // And again, at the same corner: the closure of the first round is refined now.
      const std::vector<std::uint32_t> again = slots_near(m, m.rest[m.tets[s][0]], 3);
      refine_and_check(refiner, m, again);
    }
  }
}

TEST(TetRefiner, OppositeSplitEdgesUpgradeToRed) {
  // The middle tetrahedron (a, b, c, d) shares only edge a-b with one marked tetrahedron and only
  // the opposite edge c-d with another: no green pattern closes two opposite edges, so it goes red.
  PlainMesh m = make_mesh({{0, 0, 0},
                           {0.001, 0, 0},
                           {0.0005, 0.0008, 0},
                           {0.0005, 0.0003, 0.0008},
                           {0.0005, -0.0008, 0},
                           {0.0005, -0.0003, -0.0008},
                           {0.0005, 0.0016, 0.0008},
                           {0.0012, 0.0012, 0.0006}},
                          {{0, 1, 2, 3}, {0, 1, 4, 5}, {2, 3, 6, 7}});
  m.manifold_boundary = false;  // they touch along edges only
  TetRefiner refiner(64, 64);
  const std::uint32_t marked[] = {1, 2};
  const RefinementEdit& edit = refine_and_check(refiner, m, marked);
  EXPECT_EQ(edit.removed_tetrahedra, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(edit.red_tetrahedra, 3);
  EXPECT_EQ(edit.closure_tetrahedra, 0);

  // In the cube of five, two marked corners split five edges of the central one: red again.
  PlainMesh cube = cube_of_five();
  const std::uint32_t corners[] = {1, 4};
  const RefinementEdit& cube_edit = refine_and_check(refiner, cube, corners);
  EXPECT_EQ(std::count(cube_edit.added_parent.begin(), cube_edit.added_parent.end(), 0u), 8);
}

TEST(TetRefiner, FlatNeighboursGoRedAndTheClosureReachesFarNodes) {
  // A 1 mm tetrahedron (A, B, P, D) on a flat wedge (A, B, P, E) whose far corner E lies 14 mm away,
  // 0.3 mm below the plane: closing the wedge green would make children under the dihedral floor, so
  // it goes red; so does the sliver (B, P, E, Q) beside it, which splits its edge E-Q, far from the
  // marked tetrahedron. (E, Q, S, T) shares only that edge and must be closed too.
  PlainMesh m = make_mesh({{0, 0, 0},
                           {0.001, 0, 0},
                           {0, 0.001, 0},
                           {0.0003, 0.0003, 0.001},
                           {0.01, 0.01, -0.0003},
                           {0.008, 0.008, 0.002},
                           {0.014, 0.006, 0.0},
                           {0.012, 0.012, 0.006}},
                          {{0, 1, 2, 3}, {0, 1, 2, 4}, {1, 2, 4, 5}, {4, 5, 6, 7}});
  m.manifold_boundary = false;  // the last two touch along an edge only
  TetRefiner refiner(64, 64);
  const std::uint32_t marked[] = {0};
  const RefinementEdit& edit = refine_and_check(refiner, m, marked);
  EXPECT_EQ(edit.removed_tetrahedra, (std::vector<std::uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(edit.red_tetrahedra, 3);
  EXPECT_EQ(edit.closure_tetrahedra, 1);
  const auto far_split = std::find(edit.new_node_parents.begin(), edit.new_node_parents.end(), std::array<std::uint32_t, 2>{4, 5});
  EXPECT_NE(far_split, edit.new_node_parents.end()) << "the far edge E-Q is split";
}

TEST(TetRefiner, DeterministicForShuffledAndDuplicatedMarks) {
  const PlainMesh m = tetgen_box();
  const std::vector<std::uint32_t> marked = slots_near(m, {0.01, 0.01, 0.01}, 20);
  TetRefiner refiner(m.rest.size(), m.tets.size());
  const RefinementEdit first = refiner.plan(m.view(), marked);
  std::vector<std::uint32_t> shuffled = marked;
  shuffled.insert(shuffled.end(), marked.begin(), marked.begin() + 5);
  std::mt19937 rng(7);
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  expect_same_edit(first, refiner.plan(m.view(), shuffled));
  TetRefiner fresh(16, 16);  // too small at first: grows, same answer
  expect_same_edit(first, fresh.plan(m.view(), marked));
  EXPECT_GE(first.red_tetrahedra, 20);
  EXPECT_GT(first.closure_tetrahedra, 0);
}

TEST(TetRefiner, PlansFromTheTopologyEqualThePassOverSlots) {
  // The tissue hands the refiner its node-to-tetrahedra lists; the plan must be the one the pass over
  // every slot makes, byte for byte, with dead slots about and for clusters of any size.
  PlainMesh m = from_tet_mesh(tissue_model(1296).mesh);
  TetTopology topology(m.tets, m.regions, m.rest.size(), m.tets.size(), m.rest.size());
  std::mt19937 rng(31);
  for (int k = 0; k < 40; ++k) {
    const auto t = std::uniform_int_distribution<std::uint32_t>(0, static_cast<std::uint32_t>(m.tets.size() - 1))(rng);
    if (!m.alive[t]) continue;
    m.alive[t] = 0;
    topology.remove(t);
  }
  TetRefiner over_slots(m.rest.size(), m.tets.size()), from_topology(m.rest.size(), m.tets.size());
  for (std::size_t count : {1u, 3u, 12u, 40u, 120u}) {
    const std::vector<std::uint32_t> live = live_slots(m);
    const Tetrahedron& centre = m.tets[live[std::uniform_int_distribution<std::size_t>(0, live.size() - 1)(rng)]];
    const std::vector<std::uint32_t> marked =
        slots_near(m, (m.rest[centre[0]] + m.rest[centre[1]] + m.rest[centre[2]] + m.rest[centre[3]]) * 0.25, count);
    TetMeshView with_topology = m.view();
    with_topology.topology = &topology;
    const RefinementEdit expected = over_slots.plan(m.view(), marked);
    expect_same_edit(expected, from_topology.plan(with_topology, marked));
    EXPECT_GT(expected.red_tetrahedra, 0) << count;
  }
}

TEST(TetRefiner, APlanPastItsLimitIsAbandonedAndLeavesNothingBehind) {
  // Resection asks for at most so many split tetrahedra a step and halves its marks until the plan
  // fits: a plan past the limit comes back marked and empty, and the plans after it are those a
  // fresh refiner makes (the abandoned one left no scratch set), with or without the topology.
  PlainMesh m = from_tet_mesh(tissue_model(1296).mesh);
  TetTopology topology(m.tets, m.regions, m.rest.size(), m.tets.size(), m.rest.size());
  TetMeshView with_topology = m.view();
  with_topology.topology = &topology;
  const std::vector<std::uint32_t> live = live_slots(m);
  const Tetrahedron& centre = m.tets[live[live.size() / 2]];
  const std::vector<std::uint32_t> marked =
      slots_near(m, (m.rest[centre[0]] + m.rest[centre[1]] + m.rest[centre[2]] + m.rest[centre[3]]) * 0.25, 12);
  for (const TetMeshView& view : {m.view(), with_topology}) {
    TetRefiner fresh(m.rest.size(), m.tets.size()), limited(m.rest.size(), m.tets.size());
    const RefinementEdit whole = fresh.plan(view, marked);
    const auto size = static_cast<std::size_t>(whole.red_tetrahedra + whole.closure_tetrahedra);
    ASSERT_GT(size, marked.size());
    EXPECT_FALSE(whole.exceeded);
    expect_same_edit(whole, limited.plan(view, marked, size));  // exactly at the limit: fits
    const RefinementEdit& over = limited.plan(view, marked, size - 1);
    EXPECT_TRUE(over.exceeded);
    EXPECT_TRUE(over.removed_tetrahedra.empty());
    EXPECT_TRUE(over.added_tetrahedra.empty());
    EXPECT_TRUE(over.new_node_parents.empty());
    EXPECT_EQ(over.red_tetrahedra + over.closure_tetrahedra, 0);
    const std::vector<std::uint32_t> half(marked.begin(), marked.begin() + static_cast<std::ptrdiff_t>(marked.size() / 2));
    TetRefiner another(m.rest.size(), m.tets.size());
    expect_same_edit(another.plan(view, half), limited.plan(view, half));
    expect_same_edit(whole, limited.plan(view, marked));
  }
}

TEST(TetRefiner, DeadSlotsAreIgnored) {
  PlainMesh m = tetgen_box();
  // Kill the half x > 12 mm: those slots are resected and never touched again.
  for (std::size_t s = 0; s < m.tets.size(); ++s) {
    const Tetrahedron& t = m.tets[s];
    if ((m.rest[t[0]].x + m.rest[t[1]].x + m.rest[t[2]].x + m.rest[t[3]].x) / 4.0 > 0.012) m.alive[s] = 0;
  }
  m.manifold_boundary = false;
  const std::vector<std::uint8_t> alive_before = m.alive;
  std::vector<std::uint32_t> dead_slots;
  for (std::uint32_t s = 0; s < m.tets.size(); ++s) {
    if (!m.alive[s]) dead_slots.push_back(s);
  }
  TetRefiner refiner(m.rest.size(), m.tets.size());
  // Marking only dead slots (and one out of range) plans nothing.
  dead_slots.push_back(static_cast<std::uint32_t>(m.tets.size() + 10));
  const RefinementEdit& nothing = refiner.plan(m.view(), dead_slots);
  EXPECT_TRUE(nothing.removed_tetrahedra.empty());
  EXPECT_TRUE(nothing.new_node_parents.empty());
  EXPECT_TRUE(nothing.added_tetrahedra.empty());

  // Refining at the cut face: the dead neighbours are neither removed nor closed.
  std::vector<std::uint32_t> marked = slots_near(m, {0.012, 0.01, 0.01}, 20);
  marked.insert(marked.end(), dead_slots.begin(), dead_slots.begin() + 5);
  const RefinementEdit& edit = refine_and_check(refiner, m, marked);
  for (std::uint32_t s : edit.removed_tetrahedra) EXPECT_TRUE(alive_before[s]) << "dead slot " << s << " removed";
}

TEST(TetRefiner, RandomMarksOverRepeatedRoundsStayConforming) {
  PlainMesh m = tetgen_box();
  TetRefiner refiner(m.rest.size(), m.tets.size());
  std::mt19937 rng(13);
  for (int round = 0; round < 5; ++round) {
    SCOPED_TRACE(::testing::Message() << "round " << round);
    const std::vector<std::uint32_t> live = live_slots(m);
    std::vector<std::uint32_t> marked;
    for (int k = 0; k < 6; ++k) marked.push_back(live[std::uniform_int_distribution<std::size_t>(0, live.size() - 1)(rng)]);
    refine_and_check(refiner, m, marked);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(TetRefiner, RefiningWhileCuttingOnTheGland) {
  // Resection's rhythm on the 1296 gland: each round some live slots die (cut away), then a random
  // cluster around a random live slot is refined; every plan checked and applied, 12 rounds.
  PlainMesh m = from_tet_mesh(tissue_model(1296).mesh);
  m.manifold_boundary = false;  // cutting single slots can leave tissue touching along an edge
  TetRefiner refiner(m.rest.size(), m.tets.size());
  std::mt19937 rng(2026);
  for (int round = 0; round < 12; ++round) {
    SCOPED_TRACE(::testing::Message() << "round " << round);
    std::vector<std::uint32_t> live = live_slots(m);
    auto any_live = [&] { return live[std::uniform_int_distribution<std::size_t>(0, live.size() - 1)(rng)]; };
    for (int k = 0; k < 15; ++k) m.alive[any_live()] = 0;
    live.erase(std::remove_if(live.begin(), live.end(), [&](std::uint32_t s) { return !m.alive[s]; }), live.end());
    const Tetrahedron& centre = m.tets[any_live()];
    std::vector<std::uint32_t> marked = slots_near(m, (m.rest[centre[0]] + m.rest[centre[1]] + m.rest[centre[2]] + m.rest[centre[3]]) * 0.25,
                                                   std::uniform_int_distribution<std::size_t>(1, 30)(rng));
    marked.push_back(static_cast<std::uint32_t>(m.tets.size()));  // out of range: ignored
    const std::size_t nodes_before = m.rest.size();
    const RefinementEdit& edit = refine_and_check(refiner, m, marked);
    EXPECT_EQ(edit.first_new_node, nodes_before);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(TetRefiner, FlatMeshStaysLocal) {
  // The TetGen box squashed to a twelfth of its height: every tetrahedron is flat, no green closure
  // passes the dihedral floor, and quality upgrades are capped per mark, so red stays near the marks
  // instead of spreading over the whole mesh. The result is conforming all the same.
  PlainMesh m = tetgen_box();
  for (Vec3& p : m.rest) p.z /= 12.0;
  TetRefiner refiner(m.rest.size(), m.tets.size());
  const std::vector<std::uint32_t> marked = slots_near(m, {0.01, 0.01, 0.01 / 12.0}, 10);
  const std::size_t slots = m.tets.size();
  const RefinementEdit& edit = refine_and_check(refiner, m, marked);
  EXPECT_LT(static_cast<std::size_t>(edit.red_tetrahedra), slots / 5);
  EXPECT_GT(edit.closure_tetrahedra, 0);
}

TEST(TetRefiner, MassAndUniformStrainEnergyUnchanged) {
  PlainMesh m = from_tet_mesh(tissue_model(1296).mesh);
  auto energy_and_volume = [](const PlainMesh& mesh) {
    const SpringNetwork net = build_spring_network(live_mesh(mesh));
    constexpr double kModulusPa = 30e3, kStrain = 0.01;
    double energy = 0.0, volume = 0.0;
    for (std::size_t i = 0; i < net.spring_count(); ++i) {
      const double k = edge_spring_constant(kModulusPa, net.volume_share_m3[i], net.rest_length_m[i]);
      const double stretch = kStrain * net.rest_length_m[i];
      energy += 0.5 * k * stretch * stretch;
    }
    for (double v : net.node_volume_m3) volume += v;  // lumped mass / density
    return std::pair{energy, volume};
  };
  const auto [energy_before, volume_before] = energy_and_volume(m);
  TetRefiner refiner(m.rest.size(), m.tets.size());
  const std::vector<std::uint32_t> marked = slots_near(m, {0.0, 0.012, 0.02}, 20);
  refine_and_check(refiner, m, marked);
  const auto [energy_after, volume_after] = energy_and_volume(m);
  EXPECT_NEAR(energy_after / energy_before, 1.0, 1e-12);
  EXPECT_NEAR(volume_after / volume_before, 1.0, 1e-12);
}

TEST(TetRefiner, QualityBoundedOverFourRoundsAtOnePoint) {
  // Refining the same spot four times, as the loop returning to it would. Red children keep at least
  // a fixed fraction of their parent's smallest dihedral angle (Bey: a bounded set of shapes);
  // closure children keep at least the closure floor, as any closure whose children would fall under
  // it goes red instead; so the mesh's smallest angle never drops below min(mesh's, floor) x fraction.
  PlainMesh m = from_tet_mesh(tissue_model(1296).mesh);
  const Vec3 point{0.0, 0.012, 0.02};
  TetRefiner refiner(m.rest.size(), m.tets.size());
  double mesh_min = 180.0;
  for (const Tetrahedron& t : m.tets) mesh_min = std::min(mesh_min, min_dihedral_deg(m, t));
  for (int round = 0; round < 4; ++round) {
    const PlainMesh before = m;
    const std::vector<std::uint32_t> marked = slots_near(m, point, 20);
    const RefinementEdit edit = refine_and_check(refiner, m, marked);
    double red_min = 180.0, closure_min = 180.0, red_ratio = 1e300;
    std::map<std::uint32_t, int> per_parent;
    for (std::uint32_t p : edit.added_parent) ++per_parent[p];
    for (std::size_t c = 0; c < edit.added_tetrahedra.size(); ++c) {
      const std::uint32_t parent = edit.added_parent[c];
      const double child = min_dihedral_deg(m, edit.added_tetrahedra[c]);
      if (per_parent[parent] == 8) {
        red_min = std::min(red_min, child);
        red_ratio = std::min(red_ratio, child / min_dihedral_deg(before, before.tets[parent]));
      } else {
        closure_min = std::min(closure_min, child);
      }
    }
    std::printf("round %d: %d red, %d closure, %zu nodes added; smallest dihedral of red children %.2f (>= %.3f x parent's), of closure "
                "children %.2f; mesh before %.2f\n",
                round + 1, edit.red_tetrahedra, edit.closure_tetrahedra, edit.new_node_parents.size(), red_min, red_ratio, closure_min, mesh_min);
    EXPECT_GT(red_ratio, 0.4);
    EXPECT_GE(closure_min, 9.0);
    // Local: the red region stays a small multiple of the marks.
    EXPECT_LT(edit.red_tetrahedra, 20 * 4);
  }
  double after_min = 180.0;
  for (std::size_t s = 0; s < m.tets.size(); ++s) {
    if (m.alive[s]) after_min = std::min(after_min, min_dihedral_deg(m, m.tets[s]));
  }
  EXPECT_GE(after_min, 0.4 * std::min(mesh_min, 9.0));
}

TEST(TetRefiner, NoAllocationInSteadyUse) {
  const PlainMesh m = from_tet_mesh(tissue_model(1296).mesh);
  TetRefiner refiner(m.rest.size(), m.tets.size());
  const std::vector<std::uint32_t> marked = slots_near(m, {0.0, 0.012, 0.02}, 20);
  const std::vector<std::uint32_t> other = slots_near(m, {0.005, -0.01, 0.03}, 20);
  (void)refiner.plan(m.view(), marked);  // warm-up
  testing::RealtimeProbe probe;
  const std::size_t removed = refiner.plan(m.view(), marked).removed_tetrahedra.size();
  const std::size_t removed_other = refiner.plan(m.view(), other).removed_tetrahedra.size();
  EXPECT_EQ(probe.allocations(), 0);
  EXPECT_GT(removed, 20u);
  EXPECT_GT(removed_other, 20u);
}

}  // namespace
}  // namespace resecto
