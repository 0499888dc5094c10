// Resection at a collision-step boundary: candidates near the wire, refinement, the centroid cut,
// hanging tetrahedra, chips, and the accounting by region and stroke. Every list is sorted by slot or
// node before it is acted on, so the edits, and the tissue after them, are the same on every run.
#include "rtcore/resection/resection.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace resecto {
namespace {

constexpr std::uint32_t kNoNode = 0xffffffffu;
constexpr std::size_t kNoLimit = std::numeric_limits<std::size_t>::max();

template <typename T>
void sort_unique(std::vector<T>& values) {
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
}

bool holds(const Tetrahedron& tet, std::uint32_t n) { return std::find(tet.begin(), tet.end(), n) != tet.end(); }

}  // namespace

Resection::Resection(MassSpringTissue& tissue, const ResectionConfig& config)
    : tissue_(&tissue), config_(config), refiner_(tissue.node_capacity(), tissue.topology().tetrahedron_capacity()) {
  const TetTopology& topo = tissue_->topology();
  const std::size_t slots = topo.tetrahedron_capacity();
  const std::size_t nodes = tissue_->node_capacity();
  slot_longest_.assign(slots, 0.0);
  node_reach_.assign(nodes, 0.0);
  for (std::uint32_t t = 0; t < topo.slot_count(); ++t) {
    if (!topo.alive(t)) continue;
    stats_.initial_m3[static_cast<std::size_t>(topo.region(t))] += tissue_->rest_volume_m3(t);
    slot_longest_[t] = longest_rest_edge(t);
    for (std::uint32_t n : topo.tetrahedron(t)) node_reach_[n] = std::max(node_reach_[n], slot_longest_[t]);
  }
  // The outer surface: initial faces not facing the channel's axis; its nodes, less the rim's.
  outer_node_.assign(nodes, 0);
  std::vector<std::uint8_t> on_channel(nodes, 0);
  const Vec3 axis = glm::normalize(config_.channel_direction);
  const TriangleMesh& surface = tissue_->surface();
  std::span<const Vec3> rest = tissue_->rest_positions();
  for (std::size_t s = 0; s < surface.triangles.size(); ++s) {
    if (tissue_->surface_face_owner(s) < 0) continue;
    const Triangle& tri = surface.triangles[s];
    const Vec3 n = cross(rest[tri[1]] - rest[tri[0]], rest[tri[2]] - rest[tri[0]]);
    const Vec3 c = (rest[tri[0]] + rest[tri[1]] + rest[tri[2]]) / 3.0;
    const Vec3 radial = (c - config_.channel_origin) - dot(c - config_.channel_origin, axis) * axis;
    const bool channel = dot(n, radial) < -0.3 * length(n) * length(radial);
    for (std::uint32_t v : tri) (channel ? on_channel[v] : outer_node_[v]) = 1;
  }
  for (std::size_t v = 0; v < nodes; ++v) outer_node_[v] = outer_node_[v] && !on_channel[v];

  // Dijkstra from every anchored node over the springs at rest length, ties by node: deterministic.
  anchor_distance_.assign(nodes, std::numeric_limits<double>::infinity());
  {
    const SpringNetwork& network = tissue_->network();
    std::vector<std::uint32_t> first(rest.size() + 1, 0), other;  // each node's springs' other ends
    std::vector<double> length;
    for (std::size_t s = 0; s < network.spring_count(); ++s) {
      ++first[network.spring_nodes[2 * s] + 1];
      ++first[network.spring_nodes[2 * s + 1] + 1];
    }
    for (std::size_t n = 0; n < rest.size(); ++n) first[n + 1] += first[n];
    other.resize(first.back());
    length.resize(first.back());
    std::vector<std::uint32_t> cursor(first.begin(), first.end() - 1);
    for (std::size_t s = 0; s < network.spring_count(); ++s) {
      const std::uint32_t a = network.spring_nodes[2 * s], b = network.spring_nodes[2 * s + 1];
      other[cursor[a]] = b, length[cursor[a]++] = network.rest_length_m[s];
      other[cursor[b]] = a, length[cursor[b]++] = network.rest_length_m[s];
    }
    std::vector<std::pair<double, std::uint32_t>> heap;
    for (std::uint32_t n = 0; n < rest.size(); ++n) {
      if (tissue_->anchored(n)) {
        anchor_distance_[n] = 0.0;
        heap.push_back({0.0, n});
      }
    }
    std::make_heap(heap.begin(), heap.end(), std::greater<>());
    auto relax = [&](std::uint32_t to, double d) {
      if (d < anchor_distance_[to]) {
        anchor_distance_[to] = d;
        heap.push_back({d, to});
        std::push_heap(heap.begin(), heap.end(), std::greater<>());
      }
    };
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end(), std::greater<>());
      const auto [d, n] = heap.back();
      heap.pop_back();
      if (d > anchor_distance_[n]) continue;
      for (std::uint32_t e = first[n]; e < first[n + 1]; ++e) relax(other[e], d + length[e]);
    }
  }
  frontier_.reserve(slots);

  candidates_.reserve(slots);
  near_.reserve(2 * slots);
  near_positions_.reserve(nodes);
  moved_nodes_.reserve(kMaxMovedNodes + 1);
  marked_.reserve(slots);
  by_distance_.reserve(slots);
  removing_.reserve(slots);
  queue_.reserve(slots);
  seeds_.reserve(4 * slots);
  slot_stamp_.assign(slots, 0);
  slot_level_.assign(slots, 0);
  slot_closure_.assign(slots, 0);
  child_count_.assign(slots, 0);
  child_info_.reserve(slots);
  removed_nodes_.reserve(4 * slots);
  removed_edges_.reserve(6 * slots);
  next_nodes_.reserve(nodes);
  node_stamp_.assign(nodes, 0);
  star_.reserve(4096);
  group_.reserve(4096);
  group_size_.reserve(4096);
  fan_edges_.reserve(4096);
  stats_.perforation_sites.reserve(config_.max_perforation_sites);
}

void Resection::restart_stamps() {
  std::fill(slot_stamp_.begin(), slot_stamp_.end(), 0u);
  std::fill(node_stamp_.begin(), node_stamp_.end(), 0u);
  stamp_ = 0;
}

std::uint32_t Resection::next_stamp() {
  if (++stamp_ == 0) {
    restart_stamps();
    stamp_ = 1;
  }
  return stamp_;
}

Vec3 Resection::centroid(std::uint32_t t) const {
  const Tetrahedron& tet = tissue_->topology().tetrahedron(t);
  std::span<const Vec3> x = tissue_->positions();
  return 0.25 * (x[tet[0]] + x[tet[1]] + x[tet[2]] + x[tet[3]]);
}

double Resection::longest_rest_edge(std::uint32_t t) const {
  const Tetrahedron& tet = tissue_->topology().tetrahedron(t);
  std::span<const Vec3> rest = tissue_->rest_positions();
  double longest2 = 0.0;
  for (const auto& e : kTetEdgeCorners) {
    longest2 = std::max(longest2, length_squared(rest[tet[static_cast<std::size_t>(e[0])]] - rest[tet[static_cast<std::size_t>(e[1])]]));
  }
  return std::sqrt(longest2);
}

RegionVolumes remaining_m3(const MassSpringTissue& tissue) {
  RegionVolumes out{};
  const TetTopology& topo = tissue.topology();
  for (std::uint32_t t = 0; t < topo.slot_count(); ++t) {
    if (topo.alive(t)) out[static_cast<std::size_t>(topo.region(t))] += tissue.rest_volume_m3(t);
  }
  return out;
}

RegionVolumes Resection::remaining_m3() const { return resecto::remaining_m3(*tissue_); }

ResectionStep Resection::step(const SweptVolume* sweep, bool pedal_down, bool distal, double period_s) {
  ResectionStep out;
  if (!pedal_down) in_stroke_ = false;
  if (pedal_down && !in_stroke_) {
    in_stroke_ = true;
    near_valid_ = false;  // the candidate list starts afresh with each stroke
    stroke_cut_ = stroke_perforated_ = stroke_distal_ = false;
  }
  if (sweep != nullptr) {
    gather_candidates(*sweep);
    if (config_.refine) out.refined_tetrahedra = refine_near(*sweep);
    // The cut: live candidates whose centroid the wire's path came within the radius of, by slot.
    removing_.clear();
    for (std::uint32_t t : candidates_) {
      if (tissue_->topology().alive(t) && sweep->contains(centroid(t))) removing_.push_back(t);
    }
    keep_reachable_from_surface(removing_);
    if (!removing_.empty()) {
      // A removed tetrahedron with a face on the gland's outer surface opens it.
      const TetTopology& topo = tissue_->topology();
      for (std::uint32_t t : removing_) {
        for (int f = 0; f < 4 && !out.perforated; ++f) {
          if (topo.neighbor(t, f) != TetTopology::kNone) continue;
          const Triangle face = topo.face(t, f);
          if (outer_node_[face[0]] && outer_node_[face[1]] && outer_node_[face[2]]) {
            out.perforated = true;
            if (!stroke_perforated_ && stats_.perforation_sites.size() < config_.max_perforation_sites) {
              std::span<const Vec3> x = tissue_->positions();
              stats_.perforation_sites.push_back((x[face[0]] + x[face[1]] + x[face[2]]) / 3.0);
            }
          }
        }
      }
      remove(removing_, false, out);
      // A chip's going can split the chain of tetrahedra around one of its edges: until neither
      // finds anything, hanging tetrahedra then chips again.
      for (int round = 0; round < 16; ++round) {
        remove_hanging(out);
        if (!remove_chips(out)) break;
      }
    }
  }
  removed_nodes_.clear();
  removed_edges_.clear();
  seeds_.clear();
  const bool removed = out.cut_tetrahedra + out.hanging_tetrahedra + out.chip_tetrahedra > 0;
  if (removed && !stroke_cut_) {
    stroke_cut_ = true;
    ++stats_.cuts;
  }
  if (out.perforated && !stroke_perforated_) {
    stroke_perforated_ = true;
    ++stats_.perforations;
  }
  if (removed && distal) {
    stats_.sphincter_zone_cut_s += period_s;
    if (!stroke_distal_) {
      stroke_distal_ = true;
      ++stats_.sphincter_zone_violations;
    }
  }
  if (pedal_down && !removed) stats_.loop_on_idle_s += period_s;
  const double springs = static_cast<double>(tissue_->network().spring_count());
  if (!pedal_down && static_cast<double>(tissue_->dead_spring_count()) > config_.compact_dead_spring_fraction * springs) {
    tissue_->compact_springs();
    ++stats_.spring_compactions;
  }
  return out;
}

void Resection::keep_reachable_from_surface(std::vector<std::uint32_t>& slots) {
  // The wire cuts its way in from the tissue's surface. Through the penalty contact it can sink into
  // the tissue with the pedal up; pressed there, a thin sweep can take the centroid of a tetrahedron
  // whose neighbours all stay, which would leave a closed void inside the tissue (a surface
  // component facing inwards, which no exported surface may hold). So only the tetrahedra that the
  // surface reaches, through faces of this cut's own tetrahedra, go; the rest stay for a sweep that
  // comes from the surface. Kept in their given order.
  if (slots.empty()) return;
  const TetTopology& topo = tissue_->topology();
  const std::uint32_t member = next_stamp();  // only compared for equality: a wrap between the two is harmless
  const std::uint32_t reached = next_stamp();
  for (std::uint32_t t : slots) slot_stamp_[t] = member;
  queue_.clear();
  for (std::uint32_t t : slots) {
    for (int f = 0; f < 4; ++f) {
      if (topo.neighbor(t, f) != TetTopology::kNone) continue;
      slot_stamp_[t] = reached;
      queue_.push_back(t);
      break;
    }
  }
  for (std::size_t i = 0; i < queue_.size(); ++i) {
    for (int f = 0; f < 4; ++f) {
      const std::int32_t n = topo.neighbor(queue_[i], f);
      if (n == TetTopology::kNone || slot_stamp_[static_cast<std::uint32_t>(n)] != member) continue;
      slot_stamp_[static_cast<std::uint32_t>(n)] = reached;
      queue_.push_back(static_cast<std::uint32_t>(n));
    }
  }
  std::erase_if(slots, [&](std::uint32_t t) { return slot_stamp_[t] != reached; });
}

void Resection::gather_candidates(const SweptVolume& sweep) {
  // Candidates: every live slot whose centroid is within a quarter of its longest edge of the path
  // (refine_near marks within that, and the cut needs the centroid inside), found on the skin list.
  // A slot off the list had its centroid further than the skin beyond that reach of the list's
  // path; the path has since moved at most `wire` and the radius grown by `grown`, so it can be a
  // candidate now only if its centroid moved more than what is left, which needs one of its nodes
  // to have: those nodes' stars are read directly.
  std::span<const Vec3> x = tissue_->positions();
  const double wire = near_valid_ ? sweep.sample_displacement(near_sweep_) : 0.0;
  const double left = config_.candidate_skin_m - wire - std::max(0.0, sweep.radius() - near_sweep_.radius());
  moved_nodes_.clear();
  bool valid = near_valid_ && left > 0.0 && near_.size() < near_.capacity() / 2;
  if (valid) {
    const double left2 = left * left;
    for (std::uint32_t n = 0; n < near_positions_.size() && valid; ++n) {
      if (length_squared(x[n] - near_positions_[n]) <= left2) continue;
      moved_nodes_.push_back(n);
      valid = moved_nodes_.size() <= kMaxMovedNodes;
    }
  }
  if (!valid) {
    moved_nodes_.clear();
    near_.clear();
    search_near(sweep, config_.candidate_skin_m, near_);
    near_sweep_ = sweep;
    near_positions_.assign(x.begin(), x.end());
    near_valid_ = true;
    ++near_builds_;
  }
  candidates_.clear();
  const std::uint32_t stamp = next_stamp();
  const TetTopology& topo = tissue_->topology();
  const double radius = sweep.radius();
  auto consider = [&](std::uint32_t t) {
    if (slot_stamp_[t] == stamp) return;
    slot_stamp_[t] = stamp;
    if (sweep.may_be_within(centroid(t), radius + 0.25 * slot_longest_[t])) candidates_.push_back(t);
  };
  for (std::uint32_t t : near_) {
    if (topo.alive(t)) consider(t);
  }
  for (std::uint32_t n : moved_nodes_) topo.for_each_tetrahedron_of(n, consider);
  std::sort(candidates_.begin(), candidates_.end());
}

void Resection::search_near(const SweptVolume& sweep, double extra, std::vector<std::uint32_t>& out) {
  // A centroid lies within 3/4 of the tetrahedron's longest current edge of each of its nodes, so the
  // nodes to start from are those within kNodeReach times their reach (the longest rest edge around
  // them) of the path: exact while no edge is stretched past 1.5 times its rest length, far beyond
  // what the penalty contact lets the tissue do. Only those nodes' stars are read, so the cost
  // follows the loop's neighbourhood, not the gland's size.
  constexpr double kNodeReach = 0.25 + 0.75 * 1.5;
  const std::uint32_t stamp = next_stamp();
  const TetTopology& topo = tissue_->topology();
  std::span<const Vec3> x = tissue_->positions();
  const double radius = sweep.radius() + extra;
  for (std::uint32_t n = 0; n < x.size(); ++n) {
    if (!sweep.may_be_within(x[n], radius + kNodeReach * node_reach_[n])) continue;
    topo.for_each_tetrahedron_of(n, [&](std::uint32_t t) {
      if (slot_stamp_[t] == stamp) return;
      slot_stamp_[t] = stamp;
      if (sweep.may_be_within(centroid(t), radius + 0.25 * slot_longest_[t])) out.push_back(t);
    });
  }
}

void Resection::note_refinement(std::span<const std::uint32_t> added_slots) {
  const TetTopology& topo = tissue_->topology();
  for (std::uint32_t t : added_slots) slot_longest_[t] = longest_rest_edge(t);
  const std::uint32_t stamp = next_stamp();
  for (std::uint32_t t : added_slots) {
    for (std::uint32_t n : topo.tetrahedron(t)) {
      if (node_stamp_[n] == stamp) continue;
      node_stamp_[n] = stamp;
      double reach = 0.0;
      topo.for_each_tetrahedron_of(n, [&](std::uint32_t s) { reach = std::max(reach, slot_longest_[s]); });
      node_reach_[n] = reach;
    }
  }
}

void Resection::keep_nearest_the_start(const SweptVolume& sweep, std::size_t keep_count) {
  Vec3 start(0.0);
  for (const Vec3& p : sweep.start()) start += p;
  start /= static_cast<double>(std::max<std::size_t>(1, sweep.start().size()));
  by_distance_.clear();
  for (std::uint32_t t : marked_) by_distance_.push_back({length_squared(centroid(t) - start), t});
  const auto keep = static_cast<std::ptrdiff_t>(keep_count);
  std::nth_element(by_distance_.begin(), by_distance_.begin() + keep, by_distance_.end());  // ties by slot: pairs compare both
  marked_.clear();
  for (auto it = by_distance_.begin(); it != by_distance_.begin() + keep; ++it) marked_.push_back(it->second);
  std::sort(marked_.begin(), marked_.end());
}

int Resection::refine_near(const SweptVolume& sweep) {
  int refined = 0;
  const double target = config_.target_edge_per_radius * sweep.radius();
  for (int round = 0; round < config_.max_refinement_rounds; ++round) {
    const TetTopology& topo = tissue_->topology();
    marked_.clear();
    for (std::uint32_t t : candidates_) {
      // A closure's children are not refined again (their parent's split is not regular; splitting
      // them spreads closures outward without end), nor tetrahedra already at the deepest level.
      if (!topo.alive(t) || slot_closure_[t] || slot_level_[t] >= config_.max_refinement_levels) continue;
      const double longest = slot_longest_[t];
      if (longest <= target) continue;
      // Only where the cut surface will run: a centroid within a quarter edge of the volume's rim.
      if (sweep.within(centroid(t), sweep.radius() + 0.25 * longest)) marked_.push_back(t);
    }
    if (marked_.empty()) break;
    const TetMeshView view{tissue_->rest_positions(), topo.tetrahedra(), topo.alive_flags(), topo.regions(), &topo};
    if (marked_.size() > config_.max_refined_per_step) keep_nearest_the_start(sweep, config_.max_refined_per_step);
    // A plan past the limit is abandoned as soon as it is (its spread is what costs); a single
    // marked tetrahedron is refined whatever its closure takes.
    auto plan_marked = [&] { return &refiner_.plan(view, marked_, marked_.size() > 1 ? config_.max_refined_per_step : kNoLimit); };
    const RefinementEdit* plan = plan_marked();
    while (plan->exceeded) {
      keep_nearest_the_start(sweep, marked_.size() / 2);
      plan = plan_marked();
    }
    const RefinementEdit& edit = *plan;
    if (!tissue_->can_edit(edit.new_node_parents.size(), edit.added_tetrahedra.size(), edit.removed_tetrahedra.size())) {
      ++stats_.refusals;
      break;
    }
    // Each child's level and whether it closes rather than refines (a red parent has 8 children),
    // read before the children take their slots (which may be their parents').
    for (std::uint32_t parent : edit.removed_tetrahedra) child_count_[parent] = 0;
    for (std::uint32_t parent : edit.added_parent) ++child_count_[parent];
    child_info_.clear();
    for (std::uint32_t parent : edit.added_parent) {
      const bool closure = slot_closure_[parent] || child_count_[parent] != 8;
      child_info_.push_back(static_cast<std::uint8_t>((slot_level_[parent] + 1) | (closure ? 0x80 : 0)));
    }
    tissue_->add_midpoint_nodes(edit.new_node_parents);
    for (std::size_t k = 0; k < edit.new_node_parents.size(); ++k) {
      const auto& [a, b] = edit.new_node_parents[k];
      outer_node_[edit.first_new_node + k] = outer_node_[a] && outer_node_[b];
      anchor_distance_[edit.first_new_node + k] = 0.5 * (anchor_distance_[a] + anchor_distance_[b]);
    }
    const TopologyChange change = tissue_->edit_tetrahedra(edit.removed_tetrahedra, edit.added_tetrahedra, edit.added_regions);
    if (change.refused) {
      ++stats_.refusals;
      break;
    }
    refined += edit.red_tetrahedra + edit.closure_tetrahedra;
    note_refinement(tissue_->added_slots());
    for (std::uint32_t t : tissue_->added_slots()) near_.push_back(t);  // the children replace their parents
    for (std::size_t k = 0; k < tissue_->added_slots().size(); ++k) {
      const std::uint32_t t = tissue_->added_slots()[k];
      slot_level_[t] = static_cast<std::uint8_t>(child_info_[k] & 0x7f);
      slot_closure_[t] = (child_info_[k] & 0x80) != 0;
    }
    // The candidates now: the survivors and the children, by slot.
    std::erase_if(candidates_, [&](std::uint32_t t) { return !tissue_->topology().alive(t); });
    for (std::uint32_t t : tissue_->added_slots()) candidates_.push_back(t);
    sort_unique(candidates_);
  }
  stats_.refined_tetrahedra += refined;
  return refined;
}

void Resection::remove(std::vector<std::uint32_t>& slots, bool chip, ResectionStep& out) {
  sort_unique(slots);
  const TetTopology& topo = tissue_->topology();
  RegionVolumes volume{};
  const std::size_t nodes_before = removed_nodes_.size(), edges_before = removed_edges_.size(), seeds_before = seeds_.size();
  for (std::uint32_t t : slots) {
    volume[static_cast<std::size_t>(topo.region(t))] += tissue_->rest_volume_m3(t);
    const Tetrahedron& tet = topo.tetrahedron(t);
    for (std::uint32_t n : tet) removed_nodes_.push_back(n);
    for (const auto& e : kTetEdgeCorners) {
      const std::uint32_t a = tet[static_cast<std::size_t>(e[0])], b = tet[static_cast<std::size_t>(e[1])];
      removed_edges_.push_back(static_cast<std::uint64_t>(std::min(a, b)) << 32 | std::max(a, b));
    }
    for (int f = 0; f < 4; ++f) {
      const std::int32_t n = topo.neighbor(t, f);
      if (n != TetTopology::kNone) seeds_.push_back(static_cast<std::uint32_t>(n));
    }
  }
  const TopologyChange change = tissue_->edit_tetrahedra(slots, {}, {});
  if (change.refused) {
    ++stats_.refusals;
    removed_nodes_.resize(nodes_before);
    removed_edges_.resize(edges_before);
    seeds_.resize(seeds_before);
    return;
  }
  for (std::size_t r = 1; r < volume.size(); ++r) {
    stats_.removed_m3[r] += volume[r];
    if (chip) stats_.chip_m3[r] += volume[r];
    out.removed_m3 += volume[r];
  }
  stats_.removed_tetrahedra += static_cast<std::int64_t>(slots.size());
  (chip ? out.chip_tetrahedra : out.cut_tetrahedra) += static_cast<std::int32_t>(slots.size());
}

int Resection::star_groups(std::uint32_t a, std::uint32_t b) {
  // Flood through faces that hold a (and b): two tetrahedra of the star sharing a face share them.
  const TetTopology& topo = tissue_->topology();
  group_.assign(star_.size(), -1);
  group_size_.clear();
  int groups = 0;
  for (std::size_t first = 0; first < star_.size(); ++first) {
    if (group_[first] >= 0) continue;
    group_[first] = groups;
    group_size_.push_back(1);
    queue_.clear();
    queue_.push_back(static_cast<std::uint32_t>(first));
    for (std::size_t q = 0; q < queue_.size(); ++q) {
      const std::uint32_t t = star_[queue_[q]];
      const Tetrahedron& tet = topo.tetrahedron(t);
      for (int f = 0; f < 4; ++f) {
        if (tet[static_cast<std::size_t>(f)] == a || tet[static_cast<std::size_t>(f)] == b) continue;  // the face opposite misses them
        const std::int32_t n = topo.neighbor(t, f);
        if (n == TetTopology::kNone) continue;
        const auto it = std::lower_bound(star_.begin(), star_.end(), static_cast<std::uint32_t>(n));
        if (it == star_.end() || *it != static_cast<std::uint32_t>(n)) continue;
        const auto k = static_cast<std::size_t>(it - star_.begin());
        if (group_[k] >= 0) continue;
        group_[k] = groups;
        ++group_size_.back();
        queue_.push_back(static_cast<std::uint32_t>(k));
      }
    }
    ++groups;
  }
  return groups;
}

bool Resection::vertex_fan_is_disk(std::uint32_t v) {
  // The surface faces around v, each seen from v as an edge p -> q of its link: a closed fan when
  // they chain into one cycle (no vertex of the link starts two of them).
  const TetTopology& topo = tissue_->topology();
  fan_edges_.clear();
  for (std::uint32_t t : star_) {
    const Tetrahedron& tet = topo.tetrahedron(t);
    for (int f = 0; f < 4; ++f) {
      if (tet[static_cast<std::size_t>(f)] == v || topo.neighbor(t, f) != TetTopology::kNone) continue;
      const Triangle face = topo.face(t, f);
      const int at = face[0] == v ? 0 : (face[1] == v ? 1 : 2);
      fan_edges_.push_back({face[static_cast<std::size_t>((at + 1) % 3)], face[static_cast<std::size_t>((at + 2) % 3)]});
    }
  }
  if (fan_edges_.empty()) return true;  // an inner node
  std::sort(fan_edges_.begin(), fan_edges_.end());
  for (std::size_t e = 1; e < fan_edges_.size(); ++e) {
    if (fan_edges_[e][0] == fan_edges_[e - 1][0]) return false;
  }
  std::size_t steps = 0;
  std::uint32_t at = fan_edges_[0][0];
  do {
    const auto it = std::lower_bound(fan_edges_.begin(), fan_edges_.end(), std::array<std::uint32_t, 2>{at, 0});
    if (it == fan_edges_.end() || (*it)[0] != at) return false;  // an open chain: not closed
    at = (*it)[1];
    ++steps;
  } while (at != fan_edges_[0][0] && steps <= fan_edges_.size());
  return steps == fan_edges_.size();
}

void Resection::remove_hanging(ResectionStep& out) {
  // Around every node and edge the last removals touched, in ascending order: a star in more than one
  // face-connected group keeps its largest (ties: the one with the lowest slot) and loses the rest; a
  // node whose star is one group but whose surface there is not one closed fan loses its star.
  // What goes here goes with the chips (their mass) but is no chip of its own: it is the debris a cut
  // leaves on the jagged edge of its surface, a tetrahedron or a few, dozens of them a stroke, and a
  // trainee's count of chips is of the pieces the loop cut free.
  const TetTopology& topo = tissue_->topology();
  for (int round = 0; round < 64; ++round) {
    sort_unique(removed_nodes_);
    sort_unique(removed_edges_);
    removing_.clear();
    auto drop_all_but_largest = [&](int groups) {
      int keep = 0;
      for (int g = 1; g < groups; ++g) {
        if (group_size_[static_cast<std::size_t>(g)] > group_size_[static_cast<std::size_t>(keep)]) keep = g;
      }
      for (std::size_t k = 0; k < star_.size(); ++k) {
        if (group_[k] != keep) removing_.push_back(star_[k]);
      }
    };
    for (std::uint32_t v : removed_nodes_) {
      if (topo.valence(v) == 0) continue;
      star_.clear();
      topo.for_each_tetrahedron_of(v, [&](std::uint32_t t) { star_.push_back(t); });
      std::sort(star_.begin(), star_.end());
      const int groups = star_groups(v, kNoNode);
      if (groups > 1) {
        drop_all_but_largest(groups);
      } else if (!vertex_fan_is_disk(v)) {
        for (std::uint32_t t : star_) removing_.push_back(t);
      }
    }
    for (std::uint64_t key : removed_edges_) {
      const auto a = static_cast<std::uint32_t>(key >> 32), b = static_cast<std::uint32_t>(key & 0xffffffffu);
      if (topo.valence(a) == 0 || topo.valence(b) == 0) continue;
      star_.clear();
      topo.for_each_tetrahedron_of(a, [&](std::uint32_t t) {
        if (holds(topo.tetrahedron(t), b)) star_.push_back(t);
      });
      if (star_.size() < 2) continue;
      std::sort(star_.begin(), star_.end());
      const int groups = star_groups(a, b);
      if (groups > 1) drop_all_but_largest(groups);
    }
    removed_nodes_.clear();
    removed_edges_.clear();
    if (removing_.empty()) return;
    const std::size_t before = static_cast<std::size_t>(out.chip_tetrahedra);
    remove(removing_, true, out);
    out.hanging_tetrahedra += out.chip_tetrahedra - static_cast<std::int32_t>(before);
    out.chip_tetrahedra = static_cast<std::int32_t>(before);
  }
}

bool Resection::remove_chips(ResectionStep& out) {
  // From each live neighbour of what was removed, by slot: a best-first walk through faces, nearest
  // the anchors first, until an anchored node, or a tetrahedron an earlier walk of this pass found
  // held, shows the component is held; a component that runs out first is a chip. The walk's order
  // (distance, then slot) is fixed, so the result is the same every run; only the cost depends on
  // the guide, and a held component usually shows itself within a few dozen tetrahedra.
  const TetTopology& topo = tissue_->topology();
  bool any = false;
  sort_unique(seeds_);
  if (stamp_ > 0xF0000000u) restart_stamps();  // each walk takes a stamp; keep this pass's stamps ordered
  const std::uint32_t pass = stamp_ + 1;  // stamps of this pass's walks are >= pass
  next_nodes_.clear();  // the seeds, copied: remove() appends to seeds_
  for (std::uint32_t s : seeds_) next_nodes_.push_back(s);
  seeds_.clear();
  auto priority = [&](std::uint32_t t) {
    double d = std::numeric_limits<double>::infinity();
    for (std::uint32_t n : topo.tetrahedron(t)) d = std::min(d, anchor_distance_[n]);
    return std::pair<double, std::uint32_t>{d, t};
  };
  for (std::uint32_t seed : next_nodes_) {
    if (!topo.alive(seed) || slot_stamp_[seed] >= pass) continue;
    const std::uint32_t walk = next_stamp();
    queue_.clear();  // every tetrahedron this walk reached
    frontier_.clear();
    slot_stamp_[seed] = walk;
    queue_.push_back(seed);
    frontier_.push_back(priority(seed));
    bool held = false;
    while (!frontier_.empty() && !held) {
      std::pop_heap(frontier_.begin(), frontier_.end(), std::greater<>());
      const std::uint32_t t = frontier_.back().second;
      frontier_.pop_back();
      for (std::uint32_t n : topo.tetrahedron(t)) held = held || tissue_->anchored(n);
      for (int f = 0; f < 4 && !held; ++f) {
        const std::int32_t n = topo.neighbor(t, f);
        if (n == TetTopology::kNone) continue;
        const auto u = static_cast<std::uint32_t>(n);
        if (slot_stamp_[u] == walk) continue;
        if (slot_stamp_[u] >= pass) {
          held = true;  // an earlier walk's: every chip it found is gone, so this one was held
          break;
        }
        slot_stamp_[u] = walk;
        queue_.push_back(u);
        frontier_.push_back(priority(u));
        std::push_heap(frontier_.begin(), frontier_.end(), std::greater<>());
      }
    }
    if (held) continue;
    removing_.assign(queue_.begin(), queue_.end());
    ++stats_.chips;
    remove(removing_, true, out);
    any = true;
  }
  next_nodes_.clear();
  return any;
}

}  // namespace resecto
