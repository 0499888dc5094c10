// Red-green refinement planning. Each tetrahedron is refined through "local points": its four corners
// (0-3) and the midpoints of its six edges (4-9, in kTetEdges order). Every child is four local points,
// so a child's orientation is the sign of an integer determinant of barycentric coordinates, the same
// for every geometry: children are positively oriented by construction, not by a rounding-prone test.
#include "rtcore/resection/tet_refiner.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "rtcore/geometry/vec3.h"

namespace resecto {
namespace {

constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
/// The local midpoint of the edge between corners i and j.
constexpr int kMidpoint[4][4] = {{-1, 4, 5, 6}, {4, -1, 7, 8}, {5, 7, -1, 9}, {6, 8, 9, -1}};
/// Face opposite corner k: its corners, and the mask of its edges' bits.
constexpr int kFaceCorners[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
constexpr unsigned kFaceEdgeMask[4] = {0x38u, 0x26u, 0x15u, 0x0Bu};

/// A child or face triangle as local points.
using LocalTet = std::array<int, 4>;

/// Bey's red refinement: the four corner tetrahedra, then for each octahedron diagonal (p, q) the cycle
/// of the four other midpoints around it.
constexpr LocalTet kCornerChildren[4] = {{0, 4, 5, 6}, {4, 1, 7, 8}, {5, 7, 2, 9}, {6, 8, 9, 3}};
constexpr int kDiagonals[3][2] = {{4, 9}, {5, 8}, {6, 7}};
constexpr int kEquators[3][4] = {{5, 6, 8, 7}, {4, 6, 9, 7}, {4, 5, 9, 8}};

/// Green closure needs every child's smallest dihedral angle at least this; otherwise the tetrahedron
/// is refined red, whose children stay within a constant factor of its own shape (Bey). Without it,
/// closing the same neighbour round after round would bisect its angles without bound. Just under
/// the 10 degrees TetGen is asked for: most green closures of a mesher's tetrahedra pass.
constexpr double kMinClosureDihedralDeg = 9.0;
/// Quality upgrades are optional (a green closure is always conforming), so a plan makes at most this
/// many per marked slot and closes the rest green whatever their shape: on a mesh of flat
/// tetrahedra, where no green closure passes the floor, upgrades would otherwise spread red over the
/// whole mesh. Pattern upgrades (no green closure exists) are never limited.
constexpr std::size_t kQualityUpgradesPerMark = 4;
const double kMaxClosureDihedralCos = std::cos(kMinClosureDihedralDeg * std::numbers::pi / 180.0);

constexpr std::uint32_t kNoNode = 0xffffffffu;
/// slot_state_ bits: red, waiting in to_judge_, listed in touched_.
constexpr std::uint8_t kRed = 1, kQueued = 2, kTouched = 4;
/// slot_verdict_: the split-edge mask last judged (6 bits), whether it is known, and whether green.
constexpr unsigned kVerdictMask = 0x3Fu, kVerdictKnown = 0x40u, kVerdictGreen = 0x80u;

constexpr std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a);
}

/// Twice the barycentric coordinates of local point p: small integers, so determinants are exact.
constexpr std::array<int, 4> barycentric_x2(int p) {
  std::array<int, 4> w{0, 0, 0, 0};
  if (p < 4) {
    w[p] = 2;
  } else {
    w[kTetEdges[p - 4][0]] = 1;
    w[kTetEdges[p - 4][1]] = 1;
  }
  return w;
}

/// Sign of the child's volume relative to its parent's: the sign of the determinant of its
/// barycentric rows (child volume = det / 16 x parent volume).
constexpr int orientation_of(const LocalTet& t) {
  std::array<std::array<long, 4>, 4> m{};
  for (int r = 0; r < 4; ++r) {
    const auto w = barycentric_x2(t[r]);
    for (int c = 0; c < 4; ++c) m[r][c] = w[c];
  }
  auto det3 = [&](int c0, int c1, int c2) {
    return m[1][c0] * (m[2][c1] * m[3][c2] - m[2][c2] * m[3][c1]) - m[1][c1] * (m[2][c0] * m[3][c2] - m[2][c2] * m[3][c0]) +
           m[1][c2] * (m[2][c0] * m[3][c1] - m[2][c1] * m[3][c0]);
  };
  const long det = m[0][0] * det3(1, 2, 3) - m[0][1] * det3(0, 2, 3) + m[0][2] * det3(0, 1, 3) - m[0][3] * det3(0, 1, 2);
  return (det > 0) - (det < 0);
}

/// orientation_of for every ordered quadruple of local points, indexed a * 1000 + b * 100 + c * 10 + d;
/// filled once, on first use (too many steps for the compiler's constant evaluation).
std::array<std::int8_t, 10000> make_orientation_table() {
  std::array<std::int8_t, 10000> table{};
  for (int i = 0; i < 10000; ++i) table[i] = static_cast<std::int8_t>(orientation_of({i / 1000, i / 100 % 10, i / 10 % 10, i % 10}));
  return table;
}

LocalTet oriented(LocalTet t) {
  static const std::array<std::int8_t, 10000> kOrientation = make_orientation_table();
  const int sign = kOrientation[t[0] * 1000 + t[1] * 100 + t[2] * 10 + t[3]];
  assert(sign != 0);
  if (sign < 0) std::swap(t[2], t[3]);
  return t;
}

/// The children of one tetrahedron as local points, at most eight.
struct LocalChildren {
  std::array<LocalTet, 8> tets;
  int count = 0;
  void add(const LocalTet& t) { tets[count++] = oriented(t); }
};

/// Which face holds every split edge of `mask` (the green closures), or -1 if none does (go red).
constexpr std::array<int, 64> make_green_face() {
  std::array<int, 64> face{};
  for (unsigned mask = 0; mask < 64; ++mask) {
    face[mask] = -1;
    for (int f = 0; f < 4 && mask != 0; ++f) {
      if ((mask & ~kFaceEdgeMask[f]) == 0) {
        face[mask] = f;
        break;
      }
    }
  }
  return face;
}
constexpr std::array<int, 64> kGreenFace = make_green_face();

/// A tetrahedron's corners and edge midpoints at rest, computed as the caller computes new nodes.
struct LocalGeometry {
  std::array<Vec3, 10> p;
  LocalGeometry(const Tetrahedron& tet, std::span<const Vec3> rest) {
    for (int i = 0; i < 4; ++i) p[i] = rest[tet[i]];
    for (int e = 0; e < 6; ++e) p[4 + e] = (p[kTetEdges[e][0]] + p[kTetEdges[e][1]]) * 0.5;
  }
};

void red_children(const LocalGeometry& g, LocalChildren& out) {
  for (const LocalTet& corner : kCornerChildren) out.add(corner);
  // The shortest octahedron diagonal keeps repeated refinement within a bounded set of shapes.
  int best = 0;
  double best_length = length_squared(g.p[kDiagonals[0][1]] - g.p[kDiagonals[0][0]]);
  for (int d = 1; d < 3; ++d) {
    const double l = length_squared(g.p[kDiagonals[d][1]] - g.p[kDiagonals[d][0]]);
    if (l < best_length) {
      best = d;
      best_length = l;
    }
  }
  const int p = kDiagonals[best][0], q = kDiagonals[best][1];
  for (int k = 0; k < 4; ++k) out.add({p, q, kEquators[best][k], kEquators[best][(k + 1) % 4]});
}

/// Green closure: the face opposite `apex` holds every split edge; triangulate it and cone the
/// triangles to the apex. The face's triangulation depends only on the face (its nodes' ids and
/// positions, and which edges are split), so both tetrahedra sharing it cut it the same way.
void green_children(const Tetrahedron& tet, const LocalGeometry& g, unsigned mask, int apex, LocalChildren& out) {
  const int* face = kFaceCorners[apex];
  int split_count = 0;
  std::array<bool, 3> split{};  // split[k]: edge (face[k], face[(k + 1) % 3])
  for (int k = 0; k < 3; ++k) {
    split[k] = (mask >> (kMidpoint[face[k]][face[(k + 1) % 3]] - 4) & 1u) != 0;
    split_count += split[k];
  }
  auto cone = [&](int a, int b, int c) { out.add({apex, a, b, c}); };
  if (split_count == 3) {
    const int a = face[0], b = face[1], c = face[2];
    const int ab = kMidpoint[a][b], bc = kMidpoint[b][c], ca = kMidpoint[c][a];
    cone(a, ab, ca), cone(b, bc, ab), cone(c, ca, bc), cone(ab, bc, ca);
  } else if (split_count == 1) {
    const int k = split[0] ? 0 : split[1] ? 1 : 2;
    const int a = face[k], b = face[(k + 1) % 3], c = face[(k + 2) % 3];
    const int m = kMidpoint[a][b];
    cone(a, m, c), cone(m, b, c);
  } else {
    // Edges (a, b) and (b, c) split: the corner triangle at b, then the quad a, m_ab, m_bc, c cut
    // along its shorter diagonal, ties to the diagonal from the corner with the smaller node id.
    const int k = !split[0] ? 1 : !split[1] ? 2 : 0;  // split[k] and split[k + 1] hold; b = face[k + 1]
    const int a = face[k], b = face[(k + 1) % 3], c = face[(k + 2) % 3];
    const int ab = kMidpoint[a][b], bc = kMidpoint[b][c];
    cone(ab, b, bc);
    const double from_a = length_squared(g.p[bc] - g.p[a]), from_c = length_squared(g.p[ab] - g.p[c]);
    const bool diagonal_from_a = from_a < from_c || (from_a == from_c && tet[a] < tet[c]);
    if (diagonal_from_a) {
      cone(a, ab, bc), cone(a, bc, c);
    } else {
      cone(a, ab, c), cone(ab, bc, c);
    }
  }
}

/// The largest cosine of a dihedral angle over the children: the smallest angle's cosine.
double max_dihedral_cos(const LocalGeometry& g, const LocalChildren& children) {
  constexpr int kOutwardFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  double worst = -1.0;
  for (int c = 0; c < children.count; ++c) {
    Vec3 n[4];
    double len[4];
    for (int f = 0; f < 4; ++f) {
      const Vec3& a = g.p[children.tets[c][kOutwardFaces[f][0]]];
      n[f] = cross(g.p[children.tets[c][kOutwardFaces[f][1]]] - a, g.p[children.tets[c][kOutwardFaces[f][2]]] - a);
      len[f] = length(n[f]);
    }
    for (int f = 0; f < 4; ++f) {
      for (int h = f + 1; h < 4; ++h) worst = std::max(worst, -dot(n[f], n[h]) / (len[f] * len[h]));
    }
  }
  return worst;
}

}  // namespace

TetRefiner::TetRefiner(std::size_t max_nodes, std::size_t max_tetrahedra) {
  slot_state_.assign(max_tetrahedra, 0);
  slot_mask_.assign(max_tetrahedra, 0);
  slot_verdict_.assign(max_tetrahedra, 0);
  node_is_covered_.assign(max_nodes, 0);
  node_covered_.assign(max_nodes, kNoNode);
  // A typical plan touches a few hundred tetrahedra and looks at a few thousand; larger plans grow
  // these once and keep them.
  constexpr std::size_t kTypicalSlots = 1024;
  red_slots_.reserve(kTypicalSlots);
  closure_slots_.reserve(kTypicalSlots);
  touched_.reserve(4 * kTypicalSlots);
  to_judge_.reserve(2 * kTypicalSlots);
  candidates_.reserve(8 * kTypicalSlots);
  covered_nodes_.reserve(2 * kTypicalSlots);
  incidence_offsets_.reserve(2 * kTypicalSlots + 1);
  incidence_cursor_.reserve(2 * kTypicalSlots);
  incidence_.reserve(32 * kTypicalSlots);
  split_edges_.reserve(6 * kTypicalSlots);
  edit_.new_node_parents.reserve(6 * kTypicalSlots);
  edit_.removed_tetrahedra.reserve(2 * kTypicalSlots);
  edit_.added_tetrahedra.reserve(8 * kTypicalSlots);
  edit_.added_regions.reserve(8 * kTypicalSlots);
  edit_.added_parent.reserve(8 * kTypicalSlots);
}

void TetRefiner::cover(std::uint32_t node) {
  if (node_is_covered_[node]) return;
  node_is_covered_[node] = 1;
  node_covered_[node] = static_cast<std::uint32_t>(covered_nodes_.size());
  covered_nodes_.push_back(node);
}

void TetRefiner::gather_candidates(const TetMeshView& mesh) {
  // The one pass over every slot, kept lean (a byte per node, so the flags stay in cache): the live
  // slots touching a covered node, ascending. Then, over those only, each covered node's slots,
  // ascending (a counting sort).
  candidates_.clear();
  const std::uint8_t* covered = node_is_covered_.data();
  for (std::uint32_t s = 0; s < mesh.tetrahedra.size(); ++s) {
    const Tetrahedron& t = mesh.tetrahedra[s];
    if ((covered[t[0]] | covered[t[1]] | covered[t[2]] | covered[t[3]]) && mesh.alive[s]) candidates_.push_back(s);
  }
  incidence_offsets_.assign(covered_nodes_.size() + 1, 0);
  for (std::uint32_t s : candidates_) {
    for (std::uint32_t n : mesh.tetrahedra[s]) {
      if (covered[n]) ++incidence_offsets_[node_covered_[n] + 1];
    }
  }
  for (std::size_t k = 1; k < incidence_offsets_.size(); ++k) incidence_offsets_[k] += incidence_offsets_[k - 1];
  incidence_cursor_.assign(incidence_offsets_.begin(), incidence_offsets_.end() - 1);
  incidence_.resize(incidence_offsets_.back());
  for (std::uint32_t s : candidates_) {
    for (std::uint32_t n : mesh.tetrahedra[s]) {
      if (covered[n]) incidence_[incidence_cursor_[node_covered_[n]]++] = s;
    }
  }
}

bool TetRefiner::widen_cover(const TetMeshView& mesh, std::size_t first_unsplit) {
  bool outside = false;
  for (std::size_t r = first_unsplit; r < red_slots_.size(); ++r) {
    for (std::uint32_t n : mesh.tetrahedra[red_slots_[r]]) outside |= !node_is_covered_[n];
  }
  if (!outside) return false;
  for (std::size_t c = 0, count = candidates_.size(); c < count; ++c) {
    for (std::uint32_t n : mesh.tetrahedra[candidates_[c]]) cover(n);
  }
  for (std::uint32_t s : red_slots_) {
    for (std::uint32_t n : mesh.tetrahedra[s]) cover(n);
  }
  gather_candidates(mesh);
  return true;
}

void TetRefiner::split_edge_in(const TetMeshView& mesh, std::uint32_t s, std::uint32_t a, std::uint32_t b) {
  if (slot_state_[s] & kRed) return;
  const Tetrahedron& tet = mesh.tetrahedra[s];
  const int i = static_cast<int>(std::find(tet.begin(), tet.end(), a) - tet.begin());
  const int j = static_cast<int>(std::find(tet.begin(), tet.end(), b) - tet.begin());
  slot_mask_[s] |= static_cast<std::uint8_t>(1u << (kMidpoint[i][j] - 4));
  if (!(slot_state_[s] & kTouched)) {
    slot_state_[s] |= kTouched;
    touched_.push_back(s);
  }
  if (!(slot_state_[s] & kQueued)) {
    slot_state_[s] |= kQueued;
    to_judge_.push_back(s);
  }
}

void TetRefiner::split_around(const TetMeshView& mesh, std::uint32_t red_slot) {
  const Tetrahedron& red = mesh.tetrahedra[red_slot];
  for (const auto& edge : kTetEdges) {
    const std::uint32_t a = red[edge[0]], b = red[edge[1]];
    if (mesh.topology != nullptr) {
      // The slots holding edge (a, b): those of a's live tetrahedra that hold b too.
      mesh.topology->for_each_tetrahedron_of(a, [&](std::uint32_t s) {
        const Tetrahedron& tet = mesh.tetrahedra[s];
        if (tet[0] == b || tet[1] == b || tet[2] == b || tet[3] == b) split_edge_in(mesh, s, a, b);
      });
      continue;
    }
    // The slots holding edge (a, b): the intersection of a's and b's ascending slot lists.
    const std::uint32_t* x = incidence_.data() + incidence_offsets_[node_covered_[a]];
    const std::uint32_t* x_end = incidence_.data() + incidence_offsets_[node_covered_[a] + 1];
    const std::uint32_t* y = incidence_.data() + incidence_offsets_[node_covered_[b]];
    const std::uint32_t* y_end = incidence_.data() + incidence_offsets_[node_covered_[b] + 1];
    while (x != x_end && y != y_end) {
      if (*x < *y) {
        ++x;
      } else if (*y < *x) {
        ++y;
      } else {
        split_edge_in(mesh, *x, a, b);
        ++x, ++y;
      }
    }
  }
}

const RefinementEdit& TetRefiner::plan(const TetMeshView& mesh, std::span<const std::uint32_t> marked, std::size_t limit) {
  const std::size_t slot_count = mesh.tetrahedra.size();
  const std::size_t node_count = mesh.rest_positions.size();
  if (slot_state_.size() < slot_count) {
    slot_state_.resize(slot_count, 0);
    slot_mask_.resize(slot_count, 0);
    slot_verdict_.resize(slot_count, 0);
  }
  if (node_covered_.size() < node_count) {
    node_is_covered_.resize(node_count, 0);
    node_covered_.resize(node_count, kNoNode);
  }

  edit_.first_new_node = static_cast<std::uint32_t>(node_count);
  edit_.new_node_parents.clear();
  edit_.removed_tetrahedra.clear();
  edit_.added_tetrahedra.clear();
  edit_.added_regions.clear();
  edit_.added_parent.clear();
  edit_.red_tetrahedra = edit_.closure_tetrahedra = 0;
  edit_.exceeded = false;
  red_slots_.clear();
  closure_slots_.clear();
  touched_.clear();
  split_edges_.clear();

  // The marked live slots.
  for (std::uint32_t s : marked) {
    if (s < slot_count && mesh.alive[s] && !(slot_state_[s] & kRed)) {
      slot_state_[s] = kRed | kTouched;
      red_slots_.push_back(s);
      touched_.push_back(s);
    }
  }
  if (red_slots_.empty()) return edit_;
  std::size_t quality_upgrades_left = kQualityUpgradesPerMark * red_slots_.size();

  // With the tissue's node-to-tetrahedra lists, the slots holding a split edge are read off its
  // nodes' lists. Without them, refinement is decided among the candidates: every live slot touching
  // a covered node, listed under each covered node it holds. Covered at first: the marked slots'
  // nodes (one pass over the slots). Every slot holding a split edge shares a node with a red slot,
  // so while every red node is covered the candidates hold all that refinement can reach; a red node
  // outside widens the cover by every candidate's nodes, one ring, with one more pass over the slots.
  const bool by_topology = mesh.topology != nullptr;
  if (!by_topology) {
    for (std::uint32_t s : red_slots_) {
      for (std::uint32_t n : mesh.tetrahedra[s]) cover(n);
    }
    gather_candidates(mesh);
  }

  // Closure to a fixed point. Each round splits the edges of the slots that turned red in every slot
  // holding them, then judges those slots in ascending slot order: one whose split edges admit no
  // good green closure turns red. The red set only grows, so this ends.
  std::size_t processed = 0;
  while (processed < red_slots_.size()) {
    to_judge_.clear();
    // Rare: widened, every red slot's edges are split again over the larger candidate set.
    if (!by_topology && widen_cover(mesh, processed)) processed = 0;
    for (; processed < red_slots_.size(); ++processed) split_around(mesh, red_slots_[processed]);
    // Every touched slot ends red or closed, and the touched set only grows: past the limit already,
    // the plan would be too; stop here rather than spread it further.
    if (touched_.size() > limit) {
      edit_.exceeded = true;
      clear_scratch();
      return edit_;
    }
    std::sort(to_judge_.begin(), to_judge_.end());
    for (std::uint32_t s : to_judge_) {
      slot_state_[s] &= static_cast<std::uint8_t>(~kQueued);
      if (slot_state_[s] & kRed) continue;
      // The verdict for a mask is kept: a slot's mask only grows, and most stay as they were.
      const unsigned mask = slot_mask_[s];
      std::uint8_t& verdict = slot_verdict_[s];
      if ((verdict & kVerdictMask) != mask || !(verdict & kVerdictKnown)) {
        bool green = kGreenFace[mask] >= 0;
        if (green && quality_upgrades_left > 0) {
          const Tetrahedron& tet = mesh.tetrahedra[s];
          const LocalGeometry g(tet, mesh.rest_positions);
          LocalChildren children;
          green_children(tet, g, mask, kGreenFace[mask], children);
          if (max_dihedral_cos(g, children) > kMaxClosureDihedralCos) {
            green = false;
            --quality_upgrades_left;
          }
        }
        verdict = static_cast<std::uint8_t>(mask | kVerdictKnown | (green ? kVerdictGreen : 0u));
      }
      if (!(verdict & kVerdictGreen)) {
        slot_state_[s] |= kRed;
        red_slots_.push_back(s);
      }
    }
  }

  // The closure: every touched slot (each has a split edge) that stayed green. Split edges: every red
  // slot's, numbered in ascending order; a split edge's midpoint is first_new_node + its rank.
  for (std::uint32_t s : touched_) {
    if (!(slot_state_[s] & kRed)) closure_slots_.push_back(s);
  }
  for (std::uint32_t s : red_slots_) {
    const Tetrahedron& tet = mesh.tetrahedra[s];
    for (const auto& e : kTetEdges) split_edges_.push_back(edge_key(tet[e[0]], tet[e[1]]));
  }
  std::sort(split_edges_.begin(), split_edges_.end());
  split_edges_.erase(std::unique(split_edges_.begin(), split_edges_.end()), split_edges_.end());
  for (std::uint64_t key : split_edges_) {
    edit_.new_node_parents.push_back({static_cast<std::uint32_t>(key >> 32), static_cast<std::uint32_t>(key & 0xffffffffu)});
  }
  edit_.removed_tetrahedra.insert(edit_.removed_tetrahedra.end(), red_slots_.begin(), red_slots_.end());
  edit_.removed_tetrahedra.insert(edit_.removed_tetrahedra.end(), closure_slots_.begin(), closure_slots_.end());
  std::sort(edit_.removed_tetrahedra.begin(), edit_.removed_tetrahedra.end());

  // Children slot by ascending slot, each in its pattern's fixed order: the edit is the same every run.
  for (std::uint32_t s : edit_.removed_tetrahedra) {
    const Tetrahedron& tet = mesh.tetrahedra[s];
    const LocalGeometry g(tet, mesh.rest_positions);
    LocalChildren children;
    if (slot_state_[s] & kRed) {
      red_children(g, children);
    } else {
      green_children(tet, g, slot_mask_[s], kGreenFace[slot_mask_[s]], children);
    }
    std::array<std::uint32_t, 10> node{};
    for (int i = 0; i < 4; ++i) node[i] = tet[i];
    for (int e = 0; e < 6; ++e) {
      const std::uint64_t key = edge_key(tet[kTetEdges[e][0]], tet[kTetEdges[e][1]]);
      const auto it = std::lower_bound(split_edges_.begin(), split_edges_.end(), key);
      const bool split = it != split_edges_.end() && *it == key;
      node[4 + e] = split ? edit_.first_new_node + static_cast<std::uint32_t>(it - split_edges_.begin()) : kNoNode;
    }
    for (int c = 0; c < children.count; ++c) {
      Tetrahedron child{};
      for (int i = 0; i < 4; ++i) {
        child[i] = node[children.tets[c][i]];
        assert(child[i] != kNoNode);
      }
      edit_.added_tetrahedra.push_back(child);
      edit_.added_regions.push_back(mesh.regions[s]);
      edit_.added_parent.push_back(s);
    }
  }
  edit_.red_tetrahedra = static_cast<std::int32_t>(red_slots_.size());
  edit_.closure_tetrahedra = static_cast<std::int32_t>(closure_slots_.size());

  clear_scratch();
  return edit_;
}

void TetRefiner::clear_scratch() {
  // All zero (nothing covered) for the next plan, touching only what this one set.
  for (std::uint32_t s : touched_) slot_state_[s] = slot_mask_[s] = slot_verdict_[s] = 0;
  for (std::uint32_t n : covered_nodes_) {
    node_is_covered_[n] = 0;
    node_covered_[n] = kNoNode;
  }
  covered_nodes_.clear();
}

}  // namespace resecto
