// MassSpringTissue's topology edits (resection): removing and adding tetrahedra with everything that
// hangs off them kept consistent and local. Each edit visits only the removed and added tetrahedra,
// their nodes, edges and faces; every array it grows was reserved at construction. Loops run over the
// caller's lists in their order and over the topology's lists in their stored order, so the same
// edits give the same tissue, bit for bit.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "rtcore/tissue/mass_spring.h"

namespace resecto {
namespace {

std::uint64_t mix64(std::uint64_t x) {  // splitmix64's finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}

constexpr std::uint64_t kEmptyKey = ~0ull;

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return static_cast<std::uint64_t>(std::min(a, b)) << 32 | std::max(a, b);
}

double signed_volume6(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) { return dot(b - a, cross(c - a, d - a)); }

}  // namespace

void MassSpringTissue::reserve_topology(std::size_t node_capacity, std::size_t tetrahedron_capacity) {
  const double factor = std::max(1.0, config_.topology_capacity_factor);
  for (auto* vec : {&x_, &v_, &rest_, &force_}) vec->reserve(node_capacity);
  fastest2_per_chunk_.reserve(chunks_covering(node_capacity, kNodesPerChunk));
  first_non_finite_per_chunk_.reserve(chunks_covering(node_capacity, kNodesPerChunk));
  stepped_.reserve(node_capacity, kNodesPerChunk);
  sum_schedule_.reserve(node_capacity, kNodesPerChunk);
  compressed_per_chunk_.reserve(chunks_covering(node_capacity, kNodesPerChunk) + 1);
  for (auto* vec : {&mass_, &stiffness_bound_, &damping_bound_, &step_mass_, &base_stiffness_bound_, &base_damping_bound_,
                    &network_.node_volume_m3}) {
    vec->reserve(node_capacity);
  }
  mesh_node_.reserve(node_capacity);
  tissue_node_.reserve(node_capacity);
  if (config_.integrator == TissueIntegrator::kImplicitEuler) {
    for (auto* vec : {&cg_r_, &cg_z_, &cg_p_, &cg_q_, &cg_dv_}) vec->reserve(node_capacity);
  }
  surface_.positions.reserve(node_capacity);
  searched_positions_.reserve(node_capacity);

  // Springs and faces in proportion to the tetrahedra's room (a tetrahedral mesh has about 1.2
  // edges per tetrahedron; a surface a fraction of its faces).
  spring_capacity_ = std::max(static_cast<std::size_t>(std::ceil(static_cast<double>(network_.spring_count()) * factor)),
                              network_.spring_count() + (tetrahedron_capacity - topology_.slot_count()) * 3 / 2);
  springs_.reserve(spring_capacity_, node_capacity);
  network_.spring_nodes.reserve(2 * spring_capacity_);
  network_.rest_length_m.reserve(spring_capacity_);
  network_.volume_share_m3.reserve(spring_capacity_);
  if (config_.integrator == TissueIntegrator::kImplicitEuler) {
    spring_direction_.reserve(spring_capacity_);
    spring_transverse_k_.reserve(spring_capacity_);
  }
  std::size_t table = 16;
  while (table < 2 * spring_capacity_) table *= 2;
  spring_keys_.assign(table, kEmptyKey);
  spring_values_.assign(table, 0);
  for (std::size_t s = 0; s < network_.spring_count(); ++s) {
    insert_spring_key(network_.spring_nodes[2 * s], network_.spring_nodes[2 * s + 1], static_cast<std::uint32_t>(s));
  }

  surface_face_capacity_ = std::max(static_cast<std::size_t>(std::ceil(static_cast<double>(surface_.triangle_count()) * factor)),
                                    surface_.triangle_count() + (tetrahedron_capacity - topology_.slot_count()) / 4);
  surface_.triangles.reserve(surface_face_capacity_);
  face_owner_.reserve(surface_face_capacity_);
  free_faces_.reserve(surface_face_capacity_);
  face_of_tetrahedron_.reserve(4 * tetrahedron_capacity);
  face_of_tetrahedron_.assign(4 * topology_.slot_count(), -1);

  anchor_of_node_.reserve(node_capacity);
  anchor_of_node_.assign(x_.size(), -1);
  for (std::size_t a = 0; a < network_.anchor_nodes.size(); ++a) anchor_of_node_[network_.anchor_nodes[a]] = static_cast<std::int32_t>(a);

  node_stamp_.assign(node_capacity, 0);
  dead_node_.assign(node_capacity, 0);
  touched_nodes_.reserve(node_capacity);
  spring_stamp_.assign(spring_capacity_, 0);
  touched_springs_.reserve(spring_capacity_);
  new_springs_.reserve(spring_capacity_);
  added_slots_.reserve(tetrahedron_capacity);
  slot_stamp_.assign(tetrahedron_capacity, 0);
  exposed_faces_.reserve(4 * tetrahedron_capacity);
  face_keys_.reserve(4 * tetrahedron_capacity);
  changed_face_.assign(surface_face_capacity_, 0);
  changed_faces_.reserve(surface_face_capacity_);
  tool_.reserve_tissue(node_capacity, surface_face_capacity_);
  for (SphereTree* tree : {&surface_tree_, &spare_tree_}) {
    tree->reserve(static_cast<std::int32_t>(4 * surface_face_capacity_), static_cast<std::uint32_t>(surface_face_capacity_), node_capacity);
  }
  mesh_surface_.triangles.resize(surface_face_capacity_);
  mesh_surface_.regions.resize(surface_face_capacity_);
}

std::size_t MassSpringTissue::list_mesh_surface(std::span<Triangle> triangles, std::span<TissueRegion> regions) const {
  const std::size_t room = std::min(triangles.size(), regions.size());
  std::size_t count = 0;
  for (std::size_t s = 0; s < surface_.triangles.size() && count < room; ++s) {
    const std::int64_t owner = face_owner_[s];
    if (owner < 0) continue;
    for (int c = 0; c < 3; ++c) triangles[count][c] = mesh_node_[surface_.triangles[s][c]];
    regions[count] = topology_.region(static_cast<std::uint32_t>(owner / 4));
    ++count;
  }
  return count;
}

void MassSpringTissue::refresh_mesh_surface() {
  if (mesh_surface_.version == topology_version_) return;
  mesh_surface_.count = list_mesh_surface(mesh_surface_.triangles, mesh_surface_.regions);
  mesh_surface_.version = topology_version_;
}

void MassSpringTissue::map_initial_surface() {
  // boundary_surface() wound each face outward from its tetrahedron; find that tetrahedron and face.
  surface_faces_ = surface_.triangles.size();
  face_owner_.assign(surface_faces_, -1);
  for (std::size_t s = 0; s < surface_faces_; ++s) {
    const Triangle& tri = surface_.triangles[s];
    topology_.for_each_tetrahedron_of(tri[0], [&](std::uint32_t t) {
      for (int f = 0; f < 4; ++f) {
        if (topology_.neighbor(t, f) != TetTopology::kNone) continue;
        Triangle face = topology_.face(t, f);
        if (std::find(face.begin(), face.end(), tri[1]) == face.end() || std::find(face.begin(), face.end(), tri[2]) == face.end()) continue;
        if (std::find(face.begin(), face.end(), tri[0]) == face.end()) continue;
        face_owner_[s] = 4 * static_cast<std::int64_t>(t) + f;
        face_of_tetrahedron_[4 * t + static_cast<std::uint32_t>(f)] = static_cast<std::int32_t>(s);
      }
    });
    assert(face_owner_[s] >= 0 && "a boundary face without its tetrahedron");
  }
}

std::int32_t MassSpringTissue::find_spring(std::uint32_t a, std::uint32_t b) const {
  const std::uint64_t key = edge_key(a, b);
  const std::size_t mask = spring_keys_.size() - 1;
  for (std::size_t h = mix64(key) & mask;; h = (h + 1) & mask) {
    if (spring_keys_[h] == key) return static_cast<std::int32_t>(spring_values_[h]);
    if (spring_keys_[h] == kEmptyKey) return -1;
  }
}

void MassSpringTissue::insert_spring_key(std::uint32_t a, std::uint32_t b, std::uint32_t s) {
  const std::uint64_t key = edge_key(a, b);
  const std::size_t mask = spring_keys_.size() - 1;
  std::size_t h = mix64(key) & mask;
  while (spring_keys_[h] != kEmptyKey && spring_keys_[h] != key) h = (h + 1) & mask;
  spring_keys_[h] = key;
  spring_values_[h] = s;
}

double MassSpringTissue::rest_volume_m3(std::uint32_t t) const {
  const Tetrahedron& tet = topology_.tetrahedron(t);
  return signed_volume6(rest_[tet[0]], rest_[tet[1]], rest_[tet[2]], rest_[tet[3]]) / 6.0;
}

int MassSpringTissue::recompute_spring_share(std::size_t s) {
  // A sixth of each live tetrahedron holding the edge, in the node list's stored order.
  const std::uint32_t a = network_.spring_nodes[2 * s], b = network_.spring_nodes[2 * s + 1];
  double share = 0.0;
  int holders = 0;
  topology_.for_each_tetrahedron_of(a, [&](std::uint32_t t) {
    const Tetrahedron& tet = topology_.tetrahedron(t);
    if (std::find(tet.begin(), tet.end(), b) == tet.end()) return;
    share += std::abs(rest_volume_m3(t)) / 6.0;
    ++holders;
  });
  network_.volume_share_m3[s] = share;
  return holders;
}

std::uint64_t MassSpringTissue::tetrahedron_hash(std::uint32_t t) const {
  const Tetrahedron& tet = topology_.tetrahedron(t);
  std::uint64_t h = mix64(0x7e7ull << 40 ^ t);
  for (std::uint32_t n : tet) h = mix64(h ^ n);
  return mix64(h ^ static_cast<std::uint64_t>(topology_.region(t)));
}

std::uint64_t MassSpringTissue::face_hash(std::size_t s) const {
  std::uint64_t h = mix64(0xface0000ull << 20 ^ s);
  for (std::uint32_t n : surface_.triangles[s]) h = mix64(h ^ n);
  return h;
}

void MassSpringTissue::add_surface_face(std::uint32_t t, int f) {
  std::uint32_t s;
  if (!free_faces_.empty()) {
    s = free_faces_.back();
    free_faces_.pop_back();
    surface_.triangles[s] = topology_.face(t, f);
    face_owner_[s] = 4 * static_cast<std::int64_t>(t) + f;
  } else {
    s = static_cast<std::uint32_t>(surface_.triangles.size());
    surface_.triangles.push_back(topology_.face(t, f));
    face_owner_.push_back(4 * static_cast<std::int64_t>(t) + f);
  }
  face_of_tetrahedron_[4 * t + static_cast<std::uint32_t>(f)] = static_cast<std::int32_t>(s);
  ++surface_faces_;
  topology_hash_ += face_hash(s);
  surface_tree_.insert_triangle(surface_, s);
  if (!changed_face_[s]) changed_faces_.push_back(s);
  changed_face_[s] = 1;
}

void MassSpringTissue::remove_surface_face(std::uint32_t t, int f) {
  const auto s = static_cast<std::uint32_t>(face_of_tetrahedron_[4 * t + static_cast<std::uint32_t>(f)]);
  topology_hash_ -= face_hash(s);
  surface_tree_.remove_triangle(s);
  // A free slot keeps a degenerate face on one node, so nothing reading the array trips over it.
  const std::uint32_t keep = surface_.triangles[s][0];
  surface_.triangles[s] = {keep, keep, keep};
  face_owner_[s] = -1;
  face_of_tetrahedron_[4 * t + static_cast<std::uint32_t>(f)] = -1;
  free_faces_.push_back(s);
  --surface_faces_;
  if (!changed_face_[s]) changed_faces_.push_back(s);
  changed_face_[s] = 1;
}

bool MassSpringTissue::can_edit(std::size_t nodes, std::size_t added, std::size_t removed) const {
  const std::size_t slots_after_removal = topology_.free_slots() + removed;
  return x_.size() + nodes <= topology_.node_capacity() && added <= slots_after_removal &&
         springs_.spring_count() + 6 * added <= spring_capacity_;
}

std::size_t MassSpringTissue::surface_growth_bound(std::span<const std::uint32_t> removed, std::span<const Tetrahedron> added) {
  // Faces the edit can add: the removed ones' faces toward tetrahedra that stay, and the added ones'
  // faces no other added one shares (some of which an old tetrahedron covers: an upper bound).
  std::size_t bound = 0;
  for (std::uint32_t t : removed) {
    for (int f = 0; f < 4; ++f) {
      const std::int32_t n = topology_.neighbor(t, f);
      if (n != TetTopology::kNone && slot_stamp_[static_cast<std::uint32_t>(n)] != stamp_) ++bound;
    }
  }
  face_keys_.clear();
  for (const Tetrahedron& tet : added) {
    for (const auto& corners : kTetFaceCorners) {
      std::array<std::uint32_t, 3> key{tet[static_cast<std::size_t>(corners[0])], tet[static_cast<std::size_t>(corners[1])],
                                       tet[static_cast<std::size_t>(corners[2])]};
      std::sort(key.begin(), key.end());
      face_keys_.push_back(key);
    }
  }
  std::sort(face_keys_.begin(), face_keys_.end());
  for (std::size_t k = 0; k < face_keys_.size();) {
    std::size_t same = k + 1;
    while (same < face_keys_.size() && face_keys_[same] == face_keys_[k]) ++same;
    if (same - k == 1) ++bound;
    k = same;
  }
  return bound;
}

void MassSpringTissue::add_midpoint_nodes(std::span<const std::array<std::uint32_t, 2>> parents) {
  assert(x_.size() + parents.size() <= topology_.node_capacity());
  if (edit_log_ != nullptr) edit_log_->record_midpoint_nodes(parents);
  stepped_stale_ = true;
  for (const auto& [a, b] : parents) {
    const auto node = static_cast<std::uint32_t>(x_.size());
    x_.push_back(0.5 * (x_[a] + x_[b]));
    v_.push_back(0.5 * (v_[a] + v_[b]));
    rest_.push_back(0.5 * (rest_[a] + rest_[b]));
    force_.push_back(Vec3(0.0));
    mass_.push_back(1.0);
    stiffness_bound_.push_back(0.0);
    damping_bound_.push_back(0.0);
    step_mass_.push_back(0.5 * (step_mass_[a] + step_mass_[b]));
    base_stiffness_bound_.push_back(0.0);
    base_damping_bound_.push_back(0.0);
    // The mesh's ids of the original nodes are a permutation of [0, n): a new node is n+ in both.
    mesh_node_.push_back(node);
    tissue_node_.push_back(node);
    network_.node_volume_m3.push_back(0.0);
    anchor_of_node_.push_back(-1);
    surface_.positions.push_back(x_.back());
    if (config_.integrator == TissueIntegrator::kImplicitEuler) {
      for (auto* vec : {&cg_r_, &cg_z_, &cg_p_, &cg_q_, &cg_dv_}) vec->push_back(Vec3(0.0));
    }
    topology_.add_node();
  }
  springs_.add_nodes(parents.size());
}

TopologyChange MassSpringTissue::edit_tetrahedra(std::span<const std::uint32_t> removed, std::span<const Tetrahedron> added,
                                                 std::span<const TissueRegion> added_regions) {
  TopologyChange change;
  assert(added.size() == added_regions.size());
  // New edges must get springs that keep the springs sorted by node i: each must hold a node newer
  // than every spring's node i so far (refinement's midpoints do). Checked before anything changes.
  const std::uint32_t last_i = springs_.spring_count() > 0 ? springs_.arrays().i.back() : 0;
  bool order_kept = true;
  for (const Tetrahedron& tet : added) {
    for (const auto& e : kTetEdgeCorners) {
      const std::uint32_t a = tet[static_cast<std::size_t>(e[0])], b = tet[static_cast<std::size_t>(e[1])];
      if (find_spring(a, b) < 0 && std::max(a, b) <= last_i) order_kept = false;
    }
  }
  if (++stamp_ == 0) {  // wrapped: restart the stamps
    std::fill(node_stamp_.begin(), node_stamp_.end(), 0u);
    std::fill(spring_stamp_.begin(), spring_stamp_.end(), 0u);
    std::fill(slot_stamp_.begin(), slot_stamp_.end(), 0u);
    stamp_ = 1;
  }
  for (std::uint32_t t : removed) slot_stamp_[t] = stamp_;
  if (!order_kept || !can_edit(0, added.size(), removed.size()) ||
      surface_faces_ + surface_growth_bound(removed, added) > surface_face_capacity_) {
    change.refused = true;
    ++faults_.topology_capacity_refusals;
    return change;
  }
  stepped_stale_ = true;  // nodes may lose their last tetrahedron or gain their first
  if (edit_log_ != nullptr) edit_log_->record_edit(removed, added, added_regions);
  touched_nodes_.clear();
  touched_springs_.clear();
  exposed_faces_.clear();
  added_slots_.clear();
  new_springs_.clear();
  auto touch_node = [&](std::uint32_t n) {
    if (node_stamp_[n] == stamp_) return;
    node_stamp_[n] = stamp_;
    touched_nodes_.push_back(n);
  };
  auto touch_spring = [&](std::uint32_t s) {
    if (spring_stamp_[s] == stamp_) return;
    spring_stamp_[s] = stamp_;
    touched_springs_.push_back(s);
  };

  // 1. The removed, in the caller's order: their boundary faces leave the surface; a face they share
  // with a tetrahedron that stays becomes that one's boundary once they are gone.
  for (std::uint32_t t : removed) {
    assert(topology_.alive(t));
    topology_hash_ -= tetrahedron_hash(t);
    for (int f = 0; f < 4; ++f) {
      if (face_of_tetrahedron_[4 * t + static_cast<std::uint32_t>(f)] >= 0) {
        remove_surface_face(t, f);
        ++change.surface_faces_removed;
        continue;
      }
      const std::int32_t n = topology_.neighbor(t, f);
      if (n == TetTopology::kNone || slot_stamp_[static_cast<std::uint32_t>(n)] == stamp_) continue;
      for (int g = 0; g < 4; ++g) {
        if (topology_.neighbor(static_cast<std::uint32_t>(n), g) == static_cast<std::int32_t>(t)) exposed_faces_.push_back(4 * static_cast<std::int64_t>(n) + g);
      }
    }
    const Tetrahedron& tet = topology_.tetrahedron(t);
    for (std::uint32_t n : tet) touch_node(n);
    for (const auto& e : kTetEdgeCorners) {
      const std::int32_t s = find_spring(tet[static_cast<std::size_t>(e[0])], tet[static_cast<std::size_t>(e[1])]);
      assert(s >= 0);
      touch_spring(static_cast<std::uint32_t>(s));
    }
  }
  for (std::uint32_t t : removed) topology_.remove(t);
  change.removed_tetrahedra = static_cast<std::int32_t>(removed.size());

  // 2. The added, in the caller's order; an old boundary face they cover leaves the surface.
  for (std::size_t k = 0; k < added.size(); ++k) {
    const std::uint32_t t = topology_.add(added[k], added_regions[k]);
    added_slots_.push_back(t);
    while (face_of_tetrahedron_.size() < 4 * static_cast<std::size_t>(t) + 4) face_of_tetrahedron_.push_back(-1);
    topology_hash_ += tetrahedron_hash(t);
    const Tetrahedron& tet = added[k];
    for (std::uint32_t n : tet) touch_node(n);
    for (const auto& e : kTetEdgeCorners) {
      const std::uint32_t a = tet[static_cast<std::size_t>(e[0])], b = tet[static_cast<std::size_t>(e[1])];
      const std::int32_t s = find_spring(a, b);
      if (s >= 0) {
        touch_spring(static_cast<std::uint32_t>(s));
      } else {
        // Provisional index; fixed once the new springs are sorted below.
        insert_spring_key(a, b, static_cast<std::uint32_t>(springs_.spring_count() + new_springs_.size()));
        new_springs_.push_back({std::max(a, b), std::min(a, b)});
      }
    }
    for (int f = 0; f < 4; ++f) {
      const std::int32_t n = topology_.neighbor(t, f);
      if (n == TetTopology::kNone) continue;
      for (int g = 0; g < 4; ++g) {
        const auto u = static_cast<std::uint32_t>(n);
        if (topology_.neighbor(u, g) == static_cast<std::int32_t>(t) && face_of_tetrahedron_[4 * u + static_cast<std::uint32_t>(g)] >= 0) {
          remove_surface_face(u, g);
          ++change.surface_faces_removed;
        }
      }
    }
  }
  change.added_tetrahedra = static_cast<std::int32_t>(added.size());
  // Their faces on no other tetrahedron join the surface, then the faces the removal exposed.
  for (std::uint32_t t : added_slots_) {
    for (int f = 0; f < 4; ++f) {
      if (topology_.neighbor(t, f) == TetTopology::kNone && face_of_tetrahedron_[4 * t + static_cast<std::uint32_t>(f)] < 0) {
        add_surface_face(t, f);
        ++change.surface_faces_added;
      }
    }
  }
  for (std::int64_t e : exposed_faces_) {
    const auto t = static_cast<std::uint32_t>(e / 4);
    const int f = static_cast<int>(e % 4);
    if (topology_.alive(t) && topology_.neighbor(t, f) == TetTopology::kNone && face_of_tetrahedron_[static_cast<std::size_t>(e)] < 0) {
      add_surface_face(t, f);
      ++change.surface_faces_added;
    }
  }

  // 3. New springs, sorted by (i, j) and appended: the springs stay sorted by node i.
  if (!new_springs_.empty()) {
    const std::size_t first_new = springs_.spring_count();
    std::sort(new_springs_.begin(), new_springs_.end(), [](const NewSpring& x, const NewSpring& y) { return x.i != y.i ? x.i < y.i : x.j < y.j; });
    for (const NewSpring& ns : new_springs_) {
      const auto s = static_cast<std::uint32_t>(springs_.spring_count());
      springs_.append(ns.i, ns.j, glm::length(rest_[ns.i] - rest_[ns.j]));
      network_.spring_nodes.push_back(ns.i);
      network_.spring_nodes.push_back(ns.j);
      network_.rest_length_m.push_back(springs_.arrays().rest_m.back());
      network_.volume_share_m3.push_back(0.0);
      if (config_.integrator == TissueIntegrator::kImplicitEuler) {
        spring_direction_.push_back(Vec3(0.0));
        spring_transverse_k_.push_back(0.0);
      }
      insert_spring_key(ns.i, ns.j, s);
      touch_spring(s);
      ++dead_springs_;  // until step 4 gives it its share
    }
    springs_.add_appended_to_incidence(first_new);
    change.springs_added = static_cast<std::int32_t>(new_springs_.size());
  }

  // 4. Material, locally: shares and constants of the touched springs, then volumes, masses and
  // bounds of the touched nodes (every touched spring's nodes are touched).
  const double modulus = parameters_.si(TissueParameter::kStiffness);
  const double viscosity = parameters_.si(TissueParameter::kSpringDamping);
  const double density = parameters_.si(TissueParameter::kDensity);
  const double anchor = parameters_.si(TissueParameter::kAnchorStiffness);
  const double viscous_rate = parameters_.si(TissueParameter::kViscousDamping);
  for (std::uint32_t s : touched_springs_) {
    const bool was_live = network_.volume_share_m3[s] > 0.0;
    if (recompute_spring_share(s) == 0) network_.volume_share_m3[s] = 0.0;
    const bool live = network_.volume_share_m3[s] > 0.0;
    if (was_live && !live) {
      ++change.springs_removed;
      ++dead_springs_;
    } else if (!was_live && live) {
      --dead_springs_;
    }
    update_spring_material(s, modulus, viscosity);
  }
  for (std::uint32_t n : touched_nodes_) {
    double volume = 0.0;
    topology_.for_each_tetrahedron_of(n, [&](std::uint32_t t) { volume += 0.25 * std::abs(rest_volume_m3(t)); });
    network_.node_volume_m3[n] = volume;
    if (topology_.valence(n) == 0) {
      ++change.nodes_orphaned;
      v_[n] = Vec3(0.0);
      if (edit_log_ != nullptr) edit_log_->record_orphan(n);
      dead_node_[n] = 1;
    }
    if (anchor_of_node_[n] >= 0) {
      const auto a = static_cast<std::size_t>(anchor_of_node_[n]);
      anchor_k_[a] = topology_.valence(n) > 0 ? anchor * network_.anchor_area_m2[a] : 0.0;
    }
  }
  for (std::uint32_t n : touched_nodes_) update_node_material(n, density, viscous_rate);

  // 5. Contacts on what changed, the tree's quality, the surface's version.
  tool_.invalidate_tissue(changed_face_, dead_node_);
  for (std::uint32_t s : changed_faces_) changed_face_[s] = 0;
  changed_faces_.clear();
  for (std::uint32_t n : touched_nodes_) dead_node_[n] = 0;
  if (change.surface_faces_added + change.surface_faces_removed > 0) {
    ++topology_version_;
    surface_tree_edited_ = true;  // the search's refit judges its quality (refit_surface_tree)
  }
  springs_.refresh_groups();  // for this edit and the nodes added before it, here rather than in a physics step
  return change;
}

void MassSpringTissue::refresh_stepped_nodes() {
  if (!stepped_stale_) return;
  // An orphan that no anchor holds has no force (its springs are dead, its contacts dropped) and no
  // speed (adopt_motion stops it): the bounded symplectic step would leave it where it is, so it
  // leaves it out. An anchor still pulls an orphan, and the
  // other integrators read every node's force, so those nodes stay in.
  const bool every_node = config_.integrator != TissueIntegrator::kBoundedSymplectic || !config_.skip_orphans;
  stepped_.rebuild(x_.size(), kNodesPerChunk,
                   [&](std::uint32_t n) { return every_node || topology_.valence(n) > 0 || anchor_of_node_[n] >= 0; });
  sum_schedule_.rebuild(stepped_, springs_.arrays(), springs_.incidence(), x_.size(), kNodesPerChunk);
  stepped_stale_ = false;
}

void MassSpringTissue::compact_springs() {
  std::vector<std::uint32_t>& kept = touched_springs_;  // scratch with room for every spring
  kept.clear();
  for (std::uint32_t s = 0; s < springs_.spring_count(); ++s) {
    if (network_.volume_share_m3[s] > 0.0) kept.push_back(s);
  }
  if (kept.size() == springs_.spring_count()) return;
  if (edit_log_ != nullptr) edit_log_->record_compaction();
  springs_.keep(kept, x_.size());
  stepped_stale_ = true;  // the springs' numbers changed: the spring sums' schedule with them
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const std::uint32_t s = kept[k];
    network_.spring_nodes[2 * k] = network_.spring_nodes[2 * s];
    network_.spring_nodes[2 * k + 1] = network_.spring_nodes[2 * s + 1];
    network_.rest_length_m[k] = network_.rest_length_m[s];
    network_.volume_share_m3[k] = network_.volume_share_m3[s];
    if (config_.integrator == TissueIntegrator::kImplicitEuler) {
      spring_direction_[k] = spring_direction_[s];
      spring_transverse_k_[k] = spring_transverse_k_[s];
    }
  }
  network_.spring_nodes.resize(2 * kept.size());
  network_.rest_length_m.resize(kept.size());
  network_.volume_share_m3.resize(kept.size());
  if (config_.integrator == TissueIntegrator::kImplicitEuler) {
    spring_direction_.resize(kept.size());
    spring_transverse_k_.resize(kept.size());
  }
  // The edge table maps to the new numbers; the spring stamps restart.
  std::fill(spring_keys_.begin(), spring_keys_.end(), kEmptyKey);
  for (std::size_t s = 0; s < kept.size(); ++s) {
    insert_spring_key(network_.spring_nodes[2 * s], network_.spring_nodes[2 * s + 1], static_cast<std::uint32_t>(s));
  }
  std::fill(spring_stamp_.begin(), spring_stamp_.end(), 0u);
  kept.clear();
  dead_springs_ = 0;
  ++spring_compactions_;
  springs_.refresh_groups();
}

void MassSpringTissue::replay(const TissueEditLog& log) {
  assert(edit_log_ == nullptr && "a replay is not itself recorded");
  for (const TissueEditLog::Entry& e : log.entries()) {
    switch (e.kind) {
      case TissueEditLog::Kind::kMidpointNodes: add_midpoint_nodes(log.parents(e)); break;
      case TissueEditLog::Kind::kEditTetrahedra: edit_tetrahedra(log.removed(e), log.added(e), log.regions(e)); break;
      case TissueEditLog::Kind::kCompactSprings: compact_springs(); break;
    }
  }
}

void MassSpringTissue::set_positions(std::span<const Vec3> positions) {
  assert(positions.size() <= x_.size());
  std::copy(positions.begin(), positions.end(), x_.begin());
}

void MassSpringTissue::take_search_positions() { std::copy(x_.begin(), x_.end(), surface_.positions.begin()); }

void MassSpringTissue::adopt_motion(const MassSpringTissue& front, std::span<const std::array<std::uint32_t, 2>> new_node_parents,
                                   std::span<const std::uint32_t> orphans) {
  const std::size_t shared = front.x_.size();
  assert(shared + new_node_parents.size() == x_.size());
  // A command applied to the front since this copy's job began is applied here too, before the bounds
  // of the next step are formed from the material.
  match_parameters(front.parameters_);
  std::copy(front.x_.begin(), front.x_.end(), x_.begin());
  std::copy(front.v_.begin(), front.v_.end(), v_.begin());
  std::copy(front.step_mass_.begin(), front.step_mass_.end(), step_mass_.begin());
  for (std::size_t k = 0; k < new_node_parents.size(); ++k) {
    const auto [a, b] = new_node_parents[k];
    x_[shared + k] = 0.5 * (x_[a] + x_[b]);
    v_[shared + k] = 0.5 * (v_[a] + v_[b]);
    step_mass_[shared + k] = 0.5 * (step_mass_[a] + step_mass_[b]);
  }
  for (std::uint32_t n : orphans) v_[n] = Vec3(0.0);
  travel_m_ = front.travel_m_;
  reaction_ = front.reaction_;
  const std::int64_t refusals = faults_.topology_capacity_refusals;  // this copy made the newest edits
  faults_ = front.faults_;
  faults_.topology_capacity_refusals = refusals;
  last_substeps_ = front.last_substeps_;
  last_cg_iterations_ = front.last_cg_iterations_;
  tool_.adopt_motion(front.tool_);
}

TriangleMesh MassSpringTissue::live_surface(bool rest_positions) const {
  TriangleMesh out;
  std::vector<std::int64_t> index(x_.size(), -1);
  for (std::size_t s = 0; s < surface_.triangles.size(); ++s) {
    if (face_owner_[s] < 0) continue;
    for (std::uint32_t n : surface_.triangles[s]) index[n] = 0;
  }
  for (std::size_t n = 0; n < index.size(); ++n) {
    if (index[n] < 0) continue;
    index[n] = static_cast<std::int64_t>(out.positions.size());
    out.positions.push_back(rest_positions ? rest_[n] : x_[n]);
  }
  for (std::size_t s = 0; s < surface_.triangles.size(); ++s) {
    if (face_owner_[s] < 0) continue;
    const Triangle& t = surface_.triangles[s];
    out.triangles.push_back({static_cast<std::uint32_t>(index[t[0]]), static_cast<std::uint32_t>(index[t[1]]), static_cast<std::uint32_t>(index[t[2]])});
  }
  return out;
}

}  // namespace resecto
