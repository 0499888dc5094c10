// Tool contact: candidate search (60 Hz) and penalty forces (every substep). Two kinds of point
// penetrate: tissue nodes inside a tool part, and tool vertices inside the tissue (the 0.35 mm loop
// wire is thinner than the tissue's triangles, so it would slip between nodes otherwise).
#include "rtcore/tissue/tool_contact.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include <glm/common.hpp>

#include "rtcore/geometry/closest_point.h"

namespace resecto {
namespace {

/// Barycentric weights of q, a point of triangle (a, b, c); equal thirds for a degenerate triangle.
Vec3 barycentric(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v0 = b - a, v1 = c - a, v2 = q - a;
  const double d00 = glm::dot(v0, v0), d01 = glm::dot(v0, v1), d11 = glm::dot(v1, v1);
  const double d20 = glm::dot(v2, v0), d21 = glm::dot(v2, v1);
  const double denominator = d00 * d11 - d01 * d01;
  if (!(denominator > 1e-30)) return Vec3(1.0 / 3.0);
  const double v = std::clamp((d11 * d20 - d01 * d21) / denominator, 0.0, 1.0);
  const double w = std::clamp((d00 * d21 - d01 * d20) / denominator, 0.0, 1.0 - v);
  return {1.0 - v - w, v, w};
}

/// A triangle's bounding box (low, high) from its corners.
std::pair<Vec3, Vec3> corner_box(const Vec3& a, const Vec3& b, const Vec3& c) { return {glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))}; }

bool sphere_near(const Sphere& s, const Vec3& p, double radius) {
  const double reach = s.radius + radius;
  const Vec3 d = p - s.center;
  return glm::dot(d, d) <= reach * reach;
}

/// The closest candidate is the one the point is nearest; among equally near ones (a point facing
/// an edge or vertex) the one whose plane it is furthest from decides the side, which is the
/// pseudo-normal's answer for convex corners.
struct Closest {
  static constexpr double kTie = 1e-18;  // m^2: closest points this close are the same feature
  double distance2 = 1e300;
  double reach = 1e300;  // sqrt(distance2 + kTie): a triangle whose bounding sphere is further cannot win
  /// True when no point of a triangle in the sphere (c, r) can be offered successfully (exact prune).
  bool beyond(const Vec3& p, const Vec3& center, double radius) const {
    const Vec3 d = p - center;
    return glm::dot(d, d) > (radius + reach) * (radius + reach);
  }
  /// The same for a triangle inside the box [lo, hi]: the box's distance is a lower bound of the
  /// triangle's, and needs neither a square root nor a division.
  bool beyond_box(const Vec3& p, const Vec3& lo, const Vec3& hi) const {
    const Vec3 gap = glm::max(glm::max(lo - p, p - hi), Vec3(0.0));
    return glm::dot(gap, gap) > distance2 + kTie;
  }
  /// True when a closest point at squared distance d2 cannot be offered successfully.
  bool further(double d2) const { return d2 > distance2 + kTie; }
  double plane_distance = 0.0;  // |signed distance to the plane| of the chosen triangle
  double side = 1.0;            // < 0: the point is behind the chosen triangle
  Vec3 point{0.0};
  std::uint32_t triangle = 0;
  /// A distance no candidate triangle is nearer than: the chosen one's less the tie tolerance (an
  /// equally near triangle may have lost the tie) and a picometre for the rounding of the tests.
  double clearance() const { return std::max(0.0, std::sqrt(std::max(0.0, distance2 - kTie)) - 1e-12); }
  void offer(const Vec3& p, const Vec3& q, const Vec3& unit_normal, std::uint32_t t) {
    const double d2 = glm::dot(p - q, p - q);
    const double plane = glm::dot(p - q, unit_normal);
    if (d2 < distance2 - kTie || (d2 <= distance2 + kTie && std::abs(plane) > plane_distance)) {
      distance2 = d2;
      reach = std::sqrt(d2 + kTie);
      plane_distance = std::abs(plane);
      side = plane;
      point = q;
      triangle = t;
    }
  }
};

/// The nearest of a rigid part's candidate faces to p (tool frame): each face is skipped when its
/// bounding sphere is further than the best so far (exact: same choice, fewer tests).
/// Faces come nearest first with their distance at the search (`searched`, or null), and `moved`
/// bounds how much nearer any of them can have come since: once a face's distance less that cannot
/// win, no later one can, and the scan stops.
bool cannot_win(const Closest& best, const double* searched, std::uint32_t e, double moved) {
  if (searched == nullptr) return false;
  const double lower = searched[e] - moved - 1e-12;  // a picometre for the rounding, as clearance() does
  return lower > 0.0 && lower * lower > best.distance2 + Closest::kTie;
}

Closest nearest_tool_face(const TriangleMesh& mesh, const std::vector<Vec3>& unit_normals, const std::vector<Sphere>& bounds,
                          const Vec3& p, const std::uint32_t* faces, std::uint32_t count, const double* searched = nullptr, double moved = 0.0) {
  Closest best;
  for (std::uint32_t e = 0; e < count; ++e) {
    if (cannot_win(best, searched, e, moved)) break;
    const std::uint32_t face = faces[e];
    if (best.beyond(p, bounds[face].center, bounds[face].radius)) continue;
    const Triangle& t = mesh.triangles[face];
    best.offer(p, closest_point_on_triangle(p, mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]), unit_normals[face], face);
  }
  return best;
}

/// The nearest of the tissue's candidate faces (corners at x) to w (world). The faces move, so
/// their bounds are formed here: a box, cheaper than a sphere; a face's normal only for a winner.
Closest nearest_tissue_face(const Vec3* x, const std::vector<Triangle>& triangles, const Vec3& w, const std::uint32_t* faces,
                            std::uint32_t count, const double* searched = nullptr, double moved = 0.0) {
  Closest best;
  for (std::uint32_t e = 0; e < count; ++e) {
    if (cannot_win(best, searched, e, moved)) break;
    const Triangle& t = triangles[faces[e]];
    const auto [low, high] = corner_box(x[t[0]], x[t[1]], x[t[2]]);
    if (best.beyond_box(w, low, high)) continue;
    const Vec3 q = closest_point_on_triangle(w, x[t[0]], x[t[1]], x[t[2]]);
    if (best.further(glm::dot(w - q, w - q))) continue;
    const Vec3 n2 = glm::cross(x[t[1]] - x[t[0]], x[t[2]] - x[t[0]]);
    const double length = glm::length(n2);
    best.offer(w, q, length > 0.0 ? n2 / length : Vec3(0.0), faces[e]);
  }
  return best;
}

/// The faces guard_nearest_side weighs: their corners, boxes and how high a point stands over their
/// plane (nullopt for a degenerate face). A rigid part's stand still in its frame, so their boxes and
/// unit normals were worked out once (add_part).
struct RigidFaces {
  static constexpr bool kMoving = false;
  const TriangleMesh& mesh;
  const std::vector<Vec3>& unit_normals;
  const std::vector<std::pair<Vec3, Vec3>>& boxes;
  std::array<Vec3, 3> corners(std::uint32_t face) const {
    const Triangle& t = mesh.triangles[face];
    return {mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]};
  }
  std::pair<Vec3, Vec3> box(std::uint32_t face, const std::array<Vec3, 3>&) const { return boxes[face]; }
  std::optional<double> height(std::uint32_t face, const std::array<Vec3, 3>& c, const Vec3& at, double, double&) const {
    const Vec3& normal = unit_normals[face];
    if (!(glm::dot(normal, normal) > 0.0)) return std::nullopt;
    return glm::dot(at - c[0], normal) - 1e-12;  // a picometre for the rounding
  }
};
/// The tissue's faces move, so their bounds are formed where they are, and a height must allow for the
/// plane's turning: while the corners move less than `travel_cap` (narrowed here) it turns under 30
/// degrees, and the plane moves at the point's foot by the corners' travel times the foot's barycentric
/// weights' absolute sum L, so the bound is (0.866 h) / L (guard_nearest_side).
struct TissueFaces {
  static constexpr bool kMoving = true;
  const Vec3* x;
  const std::vector<Triangle>& triangles;
  std::array<Vec3, 3> corners(std::uint32_t face) const {
    const Triangle& t = triangles[face];
    return {x[t[0]], x[t[1]], x[t[2]]};
  }
  std::pair<Vec3, Vec3> box(std::uint32_t, const std::array<Vec3, 3>& c) const {
    return corner_box(c[0], c[1], c[2]);
  }
  std::optional<double> height(std::uint32_t, const std::array<Vec3, 3>& c, const Vec3& at, double start_radius, double& travel_cap) const {
    constexpr double kTurnedHeight = 0.866;  // cos 30°, rounded down
    const Vec3 a = c[1] - c[0], b = c[2] - c[0], u = at - c[0];
    const Vec3 n2 = glm::cross(a, b);
    const double area2 = glm::length(n2);
    if (!(area2 > 0.0)) return std::nullopt;
    const double height = glm::dot(u, n2) / area2 - 1e-12;
    if (!(height > 0.0)) return height;
    // Corners moving t change n2 by at most 2t(|a| + |b|) + 4t^2; under half of |n2|, it turns < 30°.
    const double aa = glm::dot(a, a), ab = glm::dot(a, b), bb = glm::dot(b, b), ua = glm::dot(u, a), ub = glm::dot(u, b);
    travel_cap = std::min(travel_cap, 0.5 * area2 / (2.0 * (std::sqrt(aa) + std::sqrt(bb)) + 4.0 * start_radius));
    const double inverse = 1.0 / (area2 * area2);  // aa * bb - ab^2, Lagrange's identity
    const double l1 = (bb * ua - ab * ub) * inverse, l2 = (aa * ub - ab * ua) * inverse;
    const double weights = std::abs(1.0 - l1 - l2) + std::abs(l1) + std::abs(l2);
    return kTurnedHeight * height / (weights * (1.0 + 1e-9)) - 1e-12;
  }
};

/// The brute-force test a certificate stands in for decides a point's side by its nearest candidate
/// face's plane, and that answer can change without the point crossing any face: where the faces
/// are a union of overlapping shells (the tool's parts), where the tissue's surface folds through
/// itself under the loop, or where the nearest point is on an edge whose face tilts. A ball clear of
/// every face is then not enough; this cuts the certificate's radius so that the brute-force test
/// would find the point outside wherever the certificate holds (docs/commands.md, "Contact costs what
/// is in contact", gives the bounds). With the point and the faces having moved s in all, a face at
/// distance e from `at` can be the nearest only if e - d <= 2s (d the nearest's distance), and the
/// point stays in front of its plane while s < h (h its height over the plane) for a rigid face. A
/// moving face's plane also turns: while its corners move less than `travel_cap` the turn is under
/// 30 degrees, which costs h at most (1 - cos 30°), and the plane moves at the point's foot by its
/// corners' travel times the foot's barycentric weights' absolute sum L, so the bound is (0.866 h) / L.
/// Each face within reach bounds the radius by the larger of its two bounds. Faces come nearest first
/// with their distance at the search (`searched`, or null), nearer now by at most `moved`: past
/// d + 2 * radius none can overtake, and the scan stops.
template <typename Faces>
void guard_nearest_side(ToolContacts::Clearance& clearance, const Closest& best, const std::uint32_t* faces, std::uint32_t count, const double* searched,
                        double moved, const Faces& geometry) {
  constexpr double kTieDistance = 1e-9;  // m: Closest::kTie's squared tolerance as a distance, rounded up
  constexpr double kSlack = kTieDistance + 1e-12;  // and a picometre for the rounding of the tests
  const Vec3& at = clearance.at;
  const double nearest = std::sqrt(best.distance2);
  double radius = clearance.radius;
  const double start_radius = radius;
  double travel_cap = Faces::kMoving ? start_radius : std::numeric_limits<double>::infinity();
  for (std::uint32_t e = 0; e < count && radius > 0.0; ++e) {
    // The window narrows as the radius is cut; every face within the final one has been weighed.
    const double reach = nearest + 2.0 * (radius + kSlack);
    if (searched != nullptr && searched[e] - moved - 1e-12 > reach) break;
    const std::array<Vec3, 3> c = geometry.corners(faces[e]);
    const std::pair<Vec3, Vec3> box = geometry.box(faces[e], c);
    const Vec3 gap = glm::max(glm::max(box.first - at, at - box.second), Vec3(0.0));
    const double gap2 = glm::dot(gap, gap);
    if (gap2 > reach * reach) continue;
    const std::optional<double> height = geometry.height(faces[e], c, at, start_radius, travel_cap);
    if (!height) {  // a degenerate face has no side to keep
      radius = 0.0;
      break;
    }
    if (*height >= radius) continue;
    // The box's distance bounds the face's from below: the closest point only when that is not enough.
    if (0.5 * (std::sqrt(gap2) - nearest) - kSlack >= radius) continue;
    const double distance = glm::length(at - closest_point_on_triangle(at, c[0], c[1], c[2]));
    radius = std::max(0.0, std::min(radius, std::max(*height, 0.5 * (distance - nearest) - kSlack)));
  }
  clearance.radius = radius;
  clearance.travel_cap = travel_cap;
}

/// The search's certificate for a point it found at p, certified at `at` (ToolContacts::set_certify_pose),
/// `shift` = |at - p| away, from its nearest face `best` among its candidates `faces` (nearest first,
/// at distances `searched` from p): none (radius 0) when it is behind that face. Every face within the
/// margin of p is a candidate, so a ball around `at` is clear of every face, not only of the
/// candidates, up to the margin less the shift; only such a ball proves that the point stays outside
/// the other surface while it is in it. guard_nearest_side() then cuts it so that the brute-force test
/// answers "outside" throughout.
template <typename Faces>
ToolContacts::Clearance certify_within_candidates(const Closest& best, const Vec3& at, double tissue_travel, double shift, double margin,
                                                  const std::uint32_t* faces, std::uint32_t count, const double* searched, const Faces& geometry) {
  if (best.side < 0.0) return {};
  ToolContacts::Clearance clearance{at, std::max(0.0, std::min(best.clearance(), margin - shift)), tissue_travel};
  guard_nearest_side(clearance, best, faces, count, searched, shift, geometry);
  return clearance;
}

}  // namespace

bool ToolContacts::Clearance::holds(const Vec3& point, double tissue_travel_now) const {
  const double travelled = tissue_travel_now - tissue_travel;
  if (!(travelled < travel_cap)) return false;
  const double slack = radius - travelled;
  if (!(slack > 0.0)) return false;
  const Vec3 moved = point - at;
  return glm::dot(moved, moved) < slack * slack;
}

ToolContacts::ToolContacts(double margin_m, const ToolContactCapacity& capacity) : margin_m_(margin_m), capacity_(capacity) {
  // Both buffers at full capacity: publishing swaps them, so neither side ever grows.
  node_candidates_.resize(static_cast<std::size_t>(capacity.max_tissue_nodes));
  vertex_candidates_.resize(static_cast<std::size_t>(capacity.max_tool_vertices));
  pair_triangles_.resize(static_cast<std::size_t>(capacity.max_pair_entries));
  search_.nodes.resize(static_cast<std::size_t>(capacity.max_tissue_nodes));
  search_.vertices.resize(static_cast<std::size_t>(capacity.max_tool_vertices));
  search_.pair_triangles.resize(static_cast<std::size_t>(capacity.max_pair_entries));
  search_.kept.reserve(static_cast<std::size_t>(capacity.max_pair_entries));
  search_.pair_distance.resize(static_cast<std::size_t>(capacity.max_pair_entries));
  pair_distance_.resize(static_cast<std::size_t>(capacity.max_pair_entries));
  search_.node_clearance.resize(static_cast<std::size_t>(capacity.max_tissue_nodes));
  search_.vertex_clearance.resize(static_cast<std::size_t>(capacity.max_tool_vertices));
  search_.sorting.resize(static_cast<std::size_t>(std::max(capacity.max_tissue_nodes, capacity.max_tool_vertices)));
  node_clearance_.resize(static_cast<std::size_t>(capacity.max_tissue_nodes));
  vertex_clearance_.resize(static_cast<std::size_t>(capacity.max_tool_vertices));
  shares_.resize(static_cast<std::size_t>(capacity.max_tissue_nodes) + 3 * static_cast<std::size_t>(capacity.max_tool_vertices));
  stack_.reserve(256);
}

int ToolContacts::add_part(const TriangleMesh& mesh) {
  Part part;
  part.mesh = mesh;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3 n2 = triangle_normal_x2(mesh, t);
    const double length = glm::length(n2);
    part.face_normals.push_back(length > 0.0 ? n2 / length : Vec3(0.0));
    const Triangle& tri = mesh.triangles[t];
    const Vec3 centroid = (mesh.positions[tri[0]] + mesh.positions[tri[1]] + mesh.positions[tri[2]]) / 3.0;
    double radius = 0.0;
    for (std::uint32_t v : tri) radius = std::max(radius, glm::length(mesh.positions[v] - centroid));
    part.triangle_spheres.push_back({centroid, radius});
    part.face_boxes.push_back(corner_box(mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]));
  }
  part.grid.build(mesh, margin_m_);
  build_vertex_clusters(part);
  parts_.push_back(std::move(part));
  return static_cast<int>(parts_.size()) - 1;
}

void ToolContacts::build_vertex_clusters(Part& part) const {
  // Vertices binned on a grid of the margin's size, in the bins' order (the same clusters every
  // run); bins then merge, in that order, into clusters whose bound stays within kClusterMargins
  // margins. A cluster picks the tissue faces near it from the part's leaves once for all its
  // vertices: the sheath's tip ring is then a cluster or two, not a score of them.
  const double cell = margin_m_;
  std::vector<std::uint8_t> used(part.mesh.vertex_count(), 0);
  for (const Triangle& t : part.mesh.triangles) {
    for (std::uint32_t v : t) used[v] = 1;
  }
  std::map<std::array<std::int64_t, 3>, std::vector<std::uint32_t>> bins;
  for (std::uint32_t v = 0; v < part.mesh.vertex_count(); ++v) {
    if (!used[v]) continue;
    const Vec3 at = glm::floor(part.mesh.positions[v] / cell);
    bins[{static_cast<std::int64_t>(at.x), static_cast<std::int64_t>(at.y), static_cast<std::int64_t>(at.z)}].push_back(v);
  }
  std::vector<const std::vector<std::uint32_t>*> bin_vertices;
  for (const auto& [key, vertices] : bins) bin_vertices.push_back(&vertices);
  const auto bound_of = [&](const std::vector<std::uint32_t>& vertices) {
    Vec3 low(1e300), high(-1e300);
    for (std::uint32_t v : vertices) {
      low = glm::min(low, part.mesh.positions[v]);
      high = glm::max(high, part.mesh.positions[v]);
    }
    Sphere bound{0.5 * (low + high), 0.0};
    for (std::uint32_t v : vertices) bound.radius = std::max(bound.radius, glm::length(part.mesh.positions[v] - bound.center));
    return bound;
  };
  std::vector<std::uint8_t> taken(bin_vertices.size(), 0);
  std::vector<std::uint32_t> members, widened;
  for (std::size_t seed = 0; seed < bin_vertices.size(); ++seed) {
    if (taken[seed]) continue;
    members.clear();
    for (std::size_t b = seed; b < bin_vertices.size(); ++b) {
      if (taken[b]) continue;
      widened = members;
      widened.insert(widened.end(), bin_vertices[b]->begin(), bin_vertices[b]->end());
      if (b != seed && bound_of(widened).radius > kClusterMargins * margin_m_) continue;
      members.swap(widened);
      taken[b] = 1;
    }
    VertexCluster cluster;
    cluster.bound = bound_of(members);
    cluster.first = static_cast<std::uint32_t>(part.cluster_vertices.size());
    cluster.count = static_cast<std::uint32_t>(members.size());
    part.cluster_vertices.insert(part.cluster_vertices.end(), members.begin(), members.end());
    part.clusters.push_back(cluster);
  }
}

void ToolContacts::set_pose(int part, const RigidPose& pose) {
  Part& p = parts_[static_cast<std::size_t>(part)];
  p.previous_pose = p.pose;
  p.pose = pose;
}

void ToolContacts::reset_pose(int part, const RigidPose& pose) {
  Part& p = parts_[static_cast<std::size_t>(part)];
  p.previous_pose = pose;
  p.pose = pose;
}

bool ToolContacts::push_pair(std::uint32_t triangle) {
  if (search_.pair_count >= search_.pair_triangles.size()) {
    search_.stats.overflowed = true;
    return false;
  }
  search_.pair_triangles[search_.pair_count++] = triangle;
  return true;
}

void ToolContacts::gather_part_leaves(const Part& part, const SphereTree& tissue_tree, const TriangleMesh& surface) {
  part_leaves_.clear();
  near_nodes_.clear();
  if (tissue_tree.empty() || part.grid.cell_count() == 0) return;
  const RigidPose& pose = part.query_pose;
  const Vec3& lower = part.grid.lower();
  const Vec3& upper = part.grid.upper();
  const auto& spheres = tissue_tree.spheres();
  const auto& links = tissue_tree.links();
  stack_.clear();
  stack_.push_back(tissue_tree.root());
  while (!stack_.empty()) {
    const std::int32_t tree_node = stack_.back();
    stack_.pop_back();
    const Sphere& sphere = spheres[static_cast<std::size_t>(tree_node)];
    const Vec3 c = pose.inverse_apply_point(sphere.center);
    const Vec3 gap = glm::max(glm::max(lower - c, c - upper), Vec3(0.0));
    if (glm::dot(gap, gap) > sphere.radius * sphere.radius) continue;
    if (tissue_tree.is_leaf(tree_node)) {
      if (part_leaves_.size() < part_leaves_.capacity()) {
        part_leaves_.push_back({sphere, tissue_tree.pieces()[static_cast<std::size_t>(tree_node)].triangle});
      } else {
        search_.stats.overflowed = true;
      }
    } else if (stack_.size() + 2 <= stack_.capacity()) {
      stack_.push_back(links[static_cast<std::size_t>(tree_node)].right);
      stack_.push_back(links[static_cast<std::size_t>(tree_node)].left);
    } else {
      search_.stats.overflowed = true;
    }
  }
  search_.stats.tissue_leaves += static_cast<std::int32_t>(part_leaves_.size());
  // The corners as bits, read back word by word: each node once and in ascending order, so the
  // search finds them in the order the forces want them (order_points() has nothing to do) and
  // reads the positions, which the node order keeps near one another in space, in that order too.
  for (const NearLeaf& leaf : part_leaves_) {
    for (std::uint32_t n : surface.triangles[leaf.triangle]) near_node_bits_[n / 64] |= std::uint64_t{1} << (n % 64);
  }
  for (std::size_t word = 0; word < near_node_bits_.size(); ++word) {
    for (std::uint64_t bits = near_node_bits_[word]; bits != 0; bits &= bits - 1) {
      const auto n = static_cast<std::uint32_t>(64 * word + static_cast<std::size_t>(std::countr_zero(bits)));
      near_nodes_.push_back({n, pose.inverse_apply_point(surface.positions[n])});  // each node once: within the room
    }
    near_node_bits_[word] = 0;
  }
}

void ToolContacts::select_triangles(const Vec3& p, double radius, const TriangleMesh& surface) {
  near_triangles_.clear();
  near_boxes_.clear();
  const std::uint32_t mark = ++stamp_;
  const std::vector<Vec3>& x = surface.positions;
  for (const NearLeaf& leaf : part_leaves_) {
    if (!sphere_near(leaf.sphere, p, radius) || tissue_triangle_stamp_[leaf.triangle] == mark) continue;
    tissue_triangle_stamp_[leaf.triangle] = mark;
    const Triangle& t = surface.triangles[leaf.triangle];
    near_triangles_.push_back(leaf.triangle);  // each triangle once: within the room
    const auto [low, high] = corner_box(x[t[0]], x[t[1]], x[t[2]]);
    near_boxes_.push(low, high);
  }
}

namespace {
/// Up to this many kept faces are put in order by insertion: a point keeps a few to a few dozen (a
/// tissue node near the loop's wire ~20), where std::sort's partitioning only costs (the loop's search
/// 575 -> 542-553 us at 8640 in tissue_bench's BM_CollisionStep, session 40).
constexpr std::size_t kInsertionSortFaces = 48;
}  // namespace

void ToolContacts::keep_within_margin(std::uint32_t first, const Vec3& p, const std::vector<Vec3>& positions,
                                      const std::vector<Triangle>& triangles) {
  // The gathered faces over-approximate; the substeps only need those really within the margin,
  // nearest first. A tool vertex on the fine gland keeps hundreds, so they are sorted, not inserted.
  std::vector<std::uint32_t>& pairs = search_.pair_triangles;
  std::vector<KeptFace>& kept = search_.kept;
  kept.clear();
  const std::size_t count = search_.pair_count - first;
  search_.stats.pair_tests += static_cast<std::int32_t>(count);
  double* d2 = search_.pair_distance.data() + first;  // scratch until the kept ones' distances are written
  squared_distances_to_triangles(p, positions.data(), triangles.data(), &pairs[first], count, d2);
  for (std::size_t k = 0; k < count; ++k) {
    if (d2[k] <= margin_m_ * margin_m_) kept.push_back({std::bit_cast<std::uint64_t>(d2[k]), pairs[first + k]});
  }
  // By distance², ties by face index: the same order every run. A square is never negative, so its
  // bits order as the number does, and the comparisons are of integers (the doubles' compared for
  // NaN and equality too, which the profile showed as most of this sort).
  const auto before = [](const KeptFace& a, const KeptFace& b) {
    return a.distance2_bits < b.distance2_bits || (a.distance2_bits == b.distance2_bits && a.face < b.face);
  };
  if (kept.size() <= kInsertionSortFaces) {
    for (std::size_t i = 1; i < kept.size(); ++i) {
      const KeptFace face = kept[i];
      std::size_t j = i;
      for (; j > 0 && before(face, kept[j - 1]); --j) kept[j] = kept[j - 1];
      kept[j] = face;
    }
  } else {
    std::sort(kept.begin(), kept.end(), before);
  }
  for (std::size_t k = 0; k < kept.size(); ++k) {
    pairs[first + k] = kept[k].face;
    search_.pair_distance[first + k] = std::sqrt(std::bit_cast<double>(kept[k].distance2_bits));
  }
  search_.pair_count = first + kept.size();
}

void ToolContacts::latch_query_poses(double tissue_travel_m) {
  query_tissue_travel_m_ = tissue_travel_m;
  for (Part& part : parts_) {
    part.query_pose = part.certify_pose = part.pose;
    part.query_enabled = part.enabled;
  }
}

void ToolContacts::adopt_motion(const ToolContacts& front) {
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    parts_[k].pose = front.parts_[k].pose;
    parts_[k].previous_pose = front.parts_[k].previous_pose;
    parts_[k].enabled = front.parts_[k].enabled;
  }
  stats_ = front.stats_;
  points_evaluated_ = front.points_evaluated_;
  points_skipped_ = front.points_skipped_;
}

void ToolContacts::copy_query_state(const ToolContacts& front) {
  query_tissue_travel_m_ = front.query_tissue_travel_m_;
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    parts_[k].query_pose = front.parts_[k].query_pose;
    parts_[k].certify_pose = front.parts_[k].certify_pose;
    parts_[k].query_enabled = front.parts_[k].query_enabled;
  }
}

void ToolContacts::order_points(std::vector<PointCandidates>& points, std::vector<Clearance>& clearance, std::size_t count) {
  const auto in_order = [](const PointCandidates& a, const PointCandidates& b) { return a.part != b.part ? a.part < b.part : a.point < b.point; };
  if (std::is_sorted(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(count), in_order)) return;  // the tissue nodes always are
  std::vector<std::pair<PointCandidates, Clearance>>& sorting = search_.sorting;
  for (std::size_t i = 0; i < count; ++i) sorting[i] = {points[i], clearance[i]};
  const auto by_part_then_point = [&](const std::pair<PointCandidates, Clearance>& a, const std::pair<PointCandidates, Clearance>& b) {
    return in_order(a.first, b.first);
  };
  std::sort(sorting.begin(), sorting.begin() + static_cast<std::ptrdiff_t>(count), by_part_then_point);
  for (std::size_t i = 0; i < count; ++i) {
    points[i] = sorting[i].first;
    clearance[i] = sorting[i].second;
  }
}

void ToolContacts::publish_candidates() {
  std::swap(node_candidates_, search_.nodes);
  std::swap(vertex_candidates_, search_.vertices);
  std::swap(pair_triangles_, search_.pair_triangles);
  std::swap(pair_distance_, search_.pair_distance);
  candidates_travel_m_ = query_tissue_travel_m_;  // latched for that search; the next latch comes after
  distances_valid_ = true;
  for (Part& part : parts_) {
    part.published_pose = part.query_pose;
    part.published_enabled = part.query_enabled;
  }
  node_count_ = search_.node_count;
  vertex_count_ = search_.vertex_count;
  pair_count_ = search_.pair_count;
  std::swap(searched_corners_, search_.corners);
  corner_count_ = search_.corner_count;
  std::swap(node_clearance_, search_.node_clearance);
  std::swap(vertex_clearance_, search_.vertex_clearance);
  // `penetrating` belongs to the physics step that last ran, not to the search.
  const std::int32_t penetrating = stats_.penetrating;
  stats_ = search_.stats;
  stats_.penetrating = penetrating;
}

double ToolContacts::tool_shift_since_search() const {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  if (!distances_valid_) return kNever;  // nothing published yet, or an edit voided it
  double tool_shift2 = 0.0;
  for (const Part& part : parts_) {
    if (part.query_enabled != part.published_enabled) return kNever;
    if (!part.query_enabled) continue;
    for (const Vec3& v : part.mesh.positions) {
      const Vec3 d = part.query_pose.apply_point(v) - part.published_pose.apply_point(v);
      tool_shift2 = std::max(tool_shift2, glm::dot(d, d));
    }
  }
  // Rounded up, as the tissue's travel is: the shift only ever bounds a distance from above.
  return rounded_up(std::sqrt(tool_shift2));
}

void ToolContacts::search_candidates(const SphereTree& tissue_tree, const TriangleMesh& surface) {
  // Sized once for this tissue; a tissue whose size changes (resection) grows them at that step.
  if (node_stamp_.size() < surface.vertex_count()) node_stamp_.assign(surface.vertex_count(), 0);
  if (tissue_triangle_stamp_.size() < surface.triangle_count()) tissue_triangle_stamp_.assign(surface.triangle_count(), 0);
  if (near_triangles_.capacity() < surface.triangle_count()) near_triangles_.reserve(surface.triangle_count());
  if (part_leaves_.capacity() < tissue_tree.spheres().size()) part_leaves_.reserve(tissue_tree.spheres().size());
  if (near_nodes_.capacity() < surface.vertex_count()) near_nodes_.reserve(surface.vertex_count());
  if (64 * near_node_bits_.size() < surface.vertex_count()) near_node_bits_.assign((surface.vertex_count() + 63) / 64, 0);
  if (near_indices_.size() < surface.triangle_count()) {
    near_boxes_.reserve(surface.triangle_count());
    near_indices_.resize(surface.triangle_count());
  }
  if (stack_.capacity() < 4 * surface.triangle_count()) stack_.reserve(4 * surface.triangle_count());
  if (search_.corners.size() < surface.vertex_count()) search_.corners.resize(surface.vertex_count());
  if (stamp_ > 0xfff00000u) {  // keep the stamps from wrapping
    std::fill(node_stamp_.begin(), node_stamp_.end(), 0u);
    std::fill(tissue_triangle_stamp_.begin(), tissue_triangle_stamp_.end(), 0u);
    stamp_ = 0;
  }
  search_.node_count = search_.vertex_count = search_.pair_count = 0;
  search_.stats = {};
  for (std::size_t pi = 0; pi < parts_.size(); ++pi) {
    if (!parts_[pi].query_enabled) continue;
    gather_part_leaves(parts_[pi], tissue_tree, surface);
    search_tissue_nodes(static_cast<std::uint16_t>(pi), surface);
    search_tool_vertices(static_cast<std::uint16_t>(pi), surface);
  }
  collect_searched_corners(surface);
  // The points were found in the order of the tissue tree's shape, which edits, rebuilds and the copy
  // searched (Simulation's two copies of the tissue) change; in (part, point) order the forces'
  // sums, and so the state, do not depend on them.
  CandidateSet& out = search_;
  order_points(out.nodes, out.node_clearance, out.node_count);
  order_points(out.vertices, out.vertex_clearance, out.vertex_count);
  out.stats.tissue_nodes = static_cast<std::int32_t>(out.node_count);
  out.stats.tool_vertices = static_cast<std::int32_t>(out.vertex_count);
  out.stats.pair_entries = static_cast<std::int32_t>(out.pair_count);
}

void ToolContacts::collect_searched_corners(const TriangleMesh& surface) {
  CandidateSet& out = search_;
  out.corner_count = 0;
  const std::uint32_t mark = ++stamp_;
  for (std::size_t i = 0; i < out.vertex_count; ++i) {
    const PointCandidates& pc = out.vertices[i];
    for (std::uint32_t e = pc.first; e < pc.first + pc.count; ++e) {
      for (const std::uint32_t n : surface.triangles[out.pair_triangles[e]]) {
        if (node_stamp_[n] == mark) continue;
        node_stamp_[n] = mark;
        out.corners[out.corner_count++] = {n, surface.positions[n]};
      }
    }
  }
}

double ToolContacts::corners_moved(std::span<const Vec3> x) const {
  double largest2 = 0.0;
  for (std::size_t k = 0; k < corner_count_; ++k) {
    const Vec3 d = x[searched_corners_[k].node] - searched_corners_[k].at;
    largest2 = std::max(largest2, glm::dot(d, d));
  }
  // Rounded up for the subtraction's and the square root's rounding, as the tissue's travel is.
  return rounded_up(std::sqrt(largest2));
}

void ToolContacts::search_tissue_nodes(std::uint16_t part_index, const TriangleMesh& surface) {
  // A node within the margin of the part lies in the part's grid box, so the leaves of its faces
  // reach that box: the corners of the leaves gathered against the box are every such node, and the
  // grid answers which of the part's faces each may touch. The grid's cells are read a few nodes
  // ahead: they are scattered over the part's length, and waiting for each was most of the search.
  constexpr std::size_t kAhead = 8;
  const Part& part = parts_[part_index];
  CandidateSet& out = search_;
  const std::size_t count = near_nodes_.size();
  for (std::size_t i = 0; i < std::min(kAhead, count); ++i) part.grid.prefetch(near_nodes_[i].in_part);
  for (std::size_t i = 0; i < count; ++i) {
    if (i + kAhead < count) part.grid.prefetch(near_nodes_[i + kAhead].in_part);
    if (i + kAhead / 2 < count) part.grid.prefetch_list(near_nodes_[i + kAhead / 2].in_part);
    const std::uint32_t n = near_nodes_[i].node;
    const Vec3& p = near_nodes_[i].in_part;
    const std::span<const std::uint32_t> near = part.grid.candidates(p);
    if (near.empty()) continue;
    if (out.node_count >= out.nodes.size()) {
      out.stats.overflowed = true;
      continue;
    }
    const auto first = static_cast<std::uint32_t>(out.pair_count);
    for (std::uint32_t t : near) {
      if (sphere_near(part.triangle_spheres[t], p, margin_m_)) push_pair(t);
    }
    keep_within_margin(first, p, part.mesh.positions, part.mesh.triangles);
    const auto kept = static_cast<std::uint32_t>(out.pair_count - first);
    if (kept == 0) continue;
    const Vec3 at = part.certify_pose.inverse_apply_point(surface.positions[n]);
    const double shift = rounded_up(glm::length(at - p));
    const Closest best = nearest_tool_face(part.mesh, part.face_normals, part.triangle_spheres, at, &out.pair_triangles[first], kept,
                                           &out.pair_distance[first], shift);
    out.node_clearance[out.node_count] = certify_within_candidates(best, at, 0.0, shift, margin_m_, &out.pair_triangles[first], kept,
                                                                   &out.pair_distance[first], RigidFaces{part.mesh, part.face_normals, part.face_boxes});
    out.nodes[out.node_count++] = {n, part_index, first, kept, p};
  }
}

void ToolContacts::search_tool_vertices(std::uint16_t part_index, const TriangleMesh& surface) {
  // A tissue face within the margin of a vertex reaches the part's grid box (the vertex is inside
  // the part's bounding box), so the part's leaves hold it: each cluster picks the faces near it from
  // them, and each of its vertices keeps those within the margin of it.
  const Part& part = parts_[part_index];
  CandidateSet& out = search_;
  if (part_leaves_.empty()) return;
  const RigidPose& pose = part.query_pose;
  const double margin2 = margin_m_ * margin_m_;
  const std::vector<Vec3>& x = surface.positions;
  for (const VertexCluster& cluster : part.clusters) {
    select_triangles(pose.apply_point(cluster.bound.center), cluster.bound.radius + margin_m_, surface);
    if (near_triangles_.empty()) continue;
    ++out.stats.tool_clusters;
    for (std::uint32_t k = cluster.first; k < cluster.first + cluster.count; ++k) {
      const std::uint32_t v = part.cluster_vertices[k];
      if (out.vertex_count >= out.vertices.size()) {
        out.stats.overflowed = true;
        break;
      }
      const auto first = static_cast<std::uint32_t>(out.pair_count);
      const Vec3 w = pose.apply_point(part.mesh.positions[v]);
      const std::size_t within = near_boxes_.within(w, margin2, near_indices_.data());
      for (std::size_t k = 0; k < within; ++k) push_pair(near_triangles_[near_indices_[k]]);
      keep_within_margin(first, w, x, surface.triangles);
      const auto count = static_cast<std::uint32_t>(out.pair_count - first);
      if (count == 0) continue;
      const Vec3 at = part.certify_pose.apply_point(part.mesh.positions[v]);
      const double shift = rounded_up(glm::length(at - w));
      const Closest best = nearest_tissue_face(x.data(), surface.triangles, at, &out.pair_triangles[first], count, &out.pair_distance[first], shift);
      out.vertex_clearance[out.vertex_count] = certify_within_candidates(best, at, query_tissue_travel_m_, shift, margin_m_, &out.pair_triangles[first],
                                                                         count, &out.pair_distance[first], TissueFaces{x.data(), surface.triangles});
      out.vertices[out.vertex_count++] = {v, part_index, first, count, w};
    }
  }
}

void ToolContacts::apply_forces(std::span<Vec3> force, std::span<double> stiffness_bound, std::span<double> damping_bound) const {
  for (std::size_t s = 0; s < share_count_; ++s) {
    const NodeShare& share = shares_[s];
    force[share.node] += share.force;
    stiffness_bound[share.node] += share.stiffness;
    damping_bound[share.node] += share.damping;
  }
}

ToolReaction ToolContacts::evaluate_forces(std::span<const Vec3> x, std::span<const Vec3> v, const std::vector<Triangle>& surface_triangles,
                                           double k, double c, double h_s, double tissue_travel_m) {
  ToolReaction reaction;
  share_count_ = 0;  // at most one share per node candidate and three per vertex candidate: within the room
  std::int32_t penetrating = 0;
  std::int64_t skipped = 0;
  const double inverse_h = 1.0 / h_s;
  // Candidates in the order search_candidates stored them: the force sums are the same every run.
  // A tissue node is tested in the tool's frame, where the tool's triangles stand still: only the
  // node's own motion there can close its clearance.
  for (std::size_t i = 0; i < node_count_; ++i) {
    const PointCandidates& pc = node_candidates_[i];
    const Part& part = parts_[pc.part];
    const Vec3 p = part.pose.inverse_apply_point(x[pc.point]);
    if (clearance_skipping_ && node_clearance_[i].holds(p, 0.0)) {
      ++skipped;
      continue;
    }
    // In the tool's frame only the node moves.
    const double* searched = clearance_skipping_ && distances_valid_ ? &pair_distance_[pc.first] : nullptr;
    const Closest best = nearest_tool_face(part.mesh, part.face_normals, part.triangle_spheres, p, &pair_triangles_[pc.first], pc.count, searched,
                                           glm::length(p - pc.searched_at));
    if (!(best.side < 0.0)) continue;
    // Along the closest face's normal, by the distance behind its plane: the signed distance's
    // gradient there. (The closest-point direction would turn fast near the wire's centre line, a
    // transverse stiffness no step bound sees.)
    // Capped at the margin: a deeper "penetration" is a crushed or inverted face, not a contact to
    // push ever harder on (that feedback is what blew up the stiffest corner of the sweep).
    const double depth = std::min(-best.side, margin_m_);
    const Vec3 out = part.pose.apply_vector(part.face_normals[best.triangle]);
    const Vec3 surface_world = part.pose.apply_point(best.point);
    const Vec3 surface_velocity = (surface_world - part.previous_pose.apply_point(best.point)) * inverse_h;
    const double separating_speed = glm::dot(v[pc.point] - surface_velocity, out);
    const double magnitude = std::max(0.0, k * depth - c * separating_speed);
    const Vec3 f = magnitude * out;
    shares_[share_count_++] = {pc.point, f, k, c};
    reaction.force_n -= f;
    reaction.torque_nm += glm::cross(surface_world - part.pose.translation, -f);
    ++penetrating;
  }
  // How much nearer a tool vertex's candidate faces can have come since the search: at most as far
  // as their corners have moved from where the search saw them. That displacement is far smaller
  // than the tissue's travel since the search, a sum over steps of the fastest node anywhere, which
  // counts every oscillation; the scans below stop sooner with it, and choose the same faces.
  // Measured at the first vertex its certificate does not skip: a step where all are skipped scans none.
  double faces_moved = 0.0;
  bool faces_measured = false;
  for (std::size_t i = 0; i < vertex_count_; ++i) {
    const PointCandidates& pc = vertex_candidates_[i];
    const Part& part = parts_[pc.part];
    const Vec3 w = part.pose.apply_point(part.mesh.positions[pc.point]);
    if (clearance_skipping_ && vertex_clearance_[i].holds(w, tissue_travel_m)) {
      ++skipped;
      continue;
    }
    // The vertex's own motion and its faces' since the search.
    const double* searched = clearance_skipping_ && distances_valid_ ? &pair_distance_[pc.first] : nullptr;
    if (!faces_measured) {
      faces_moved = tissue_travel_m - candidates_travel_m_;
      if (searched != nullptr) faces_moved = std::min(faces_moved, corners_moved(x));
      faces_measured = true;
    }
    const Closest best = nearest_tissue_face(x.data(), surface_triangles, w, &pair_triangles_[pc.first], pc.count, searched,
                                             glm::length(w - pc.searched_at) + faces_moved);
    if (!(best.side < 0.0)) continue;
    const Triangle& t = surface_triangles[best.triangle];
    const double depth = std::min(-best.side, margin_m_);
    // Into the tissue along the closest face's inward normal (the signed distance's gradient).
    const Vec3 n2 = glm::cross(x[t[1]] - x[t[0]], x[t[2]] - x[t[0]]);
    const Vec3 in = -n2 / glm::length(n2);
    const Vec3 weights = barycentric(best.point, x[t[0]], x[t[1]], x[t[2]]);
    const Vec3 tissue_velocity = weights[0] * v[t[0]] + weights[1] * v[t[1]] + weights[2] * v[t[2]];
    const Vec3 tool_velocity = (w - part.previous_pose.apply_point(part.mesh.positions[pc.point])) * inverse_h;
    const double approach_speed = glm::dot(tool_velocity - tissue_velocity, in);
    const double magnitude = std::max(0.0, k * depth + c * approach_speed);
    const Vec3 f = magnitude * in;
    for (int corner = 0; corner < 3; ++corner) shares_[share_count_++] = {t[corner], weights[corner] * f, weights[corner] * k, weights[corner] * c};
    reaction.force_n -= f;
    reaction.torque_nm += glm::cross(w - part.pose.translation, -f);
    ++penetrating;
  }
  stats_.penetrating = penetrating;
  points_skipped_ += skipped;
  points_evaluated_ += static_cast<std::int64_t>(node_count_ + vertex_count_) - skipped;
  return reaction;
}

void ToolContacts::invalidate_tissue(std::span<const std::uint8_t> changed_face, std::span<const std::uint8_t> dead_node) {
  distances_valid_ = false;  // measured against a surface that is not the one now
  // In stored order, compacting each point's pairs in place: the survivors keep their order.
  for (std::size_t i = 0; i < node_count_; ++i) {
    PointCandidates& pc = node_candidates_[i];
    if (pc.point < dead_node.size() && dead_node[pc.point]) pc.count = 0;
    node_clearance_[i].radius = 0.0;
  }
  for (std::size_t i = 0; i < vertex_count_; ++i) {
    PointCandidates& pc = vertex_candidates_[i];
    std::uint32_t kept = 0;
    for (std::uint32_t e = 0; e < pc.count; ++e) {
      const std::uint32_t face = pair_triangles_[pc.first + e];
      if (face < changed_face.size() && changed_face[face]) continue;
      pair_triangles_[pc.first + kept++] = face;
    }
    pc.count = kept;
    vertex_clearance_[i].radius = 0.0;
  }
}

void ToolContacts::reserve_tissue(std::size_t max_nodes, std::size_t max_faces) {
  if (node_stamp_.size() < max_nodes) node_stamp_.assign(max_nodes, 0);
  if (tissue_triangle_stamp_.size() < max_faces) tissue_triangle_stamp_.assign(max_faces, 0);
  near_triangles_.reserve(max_faces);
  near_boxes_.reserve(max_faces);
  if (near_indices_.size() < max_faces) near_indices_.resize(max_faces);
  part_leaves_.reserve(2 * max_faces);  // a tree has fewer leaves than nodes; a leaf or two per face
  near_nodes_.reserve(max_nodes);
  if (64 * near_node_bits_.size() < max_nodes) near_node_bits_.assign((max_nodes + 63) / 64, 0);
  // Both buffers: publishing swaps them.
  if (search_.corners.size() < max_nodes) search_.corners.resize(max_nodes);
  if (searched_corners_.size() < max_nodes) searched_corners_.resize(max_nodes);
  // A tissue tree has about two nodes per leaf and a leaf or two per face: a depth-first stack never
  // holds more than the tree's nodes.
  stack_.reserve(4 * max_faces);
}

}  // namespace resecto
