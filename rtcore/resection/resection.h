// Resection: the loop cutting tissue away at a collision-step boundary (DESIGN.md "Resection", the
// paper's section 3 "mesh modification after tissue cuttings" and its local-refinement next step).
//
// The rule. While the pedal is down and the loop is out of the sheath, the wire sweeps a volume
// between consecutive collision steps (swept_volume.h). Tetrahedra near it are first refined (1:8
// with a conforming closure, tet_refiner.h) until their longest rest edge is at most the target
// (a multiple of the cutting radius); then every live tetrahedron whose centroid, at the current
// positions, lies inside the swept volume is removed. The centroid rule after refinement is exact
// in the limit of small tetrahedra (the removed volume converges to the swept volume from both
// sides, errors cancel across the cut surface), needs one distance query per tetrahedron, and can
// never remove a tetrahedron the wire did not come within the radius of its centre; a volume-fraction
// rule would need clipping against the swept volume for the same limit.
//
// Afterwards the remaining tissue is kept a closed, consistently oriented 2-manifold: tetrahedra left
// hanging by an edge or a vertex go (the smaller face-connected group around that edge or vertex),
// and face-connected components holding no anchored node become chips. Every removal is accounted by
// region (rest volume; grams at the live density).
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "rtcore/resection/swept_volume.h"
#include "rtcore/resection/tet_refiner.h"
#include "rtcore/tissue/mass_spring.h"

namespace resecto {

struct ResectionConfig {
  /// Refines tetrahedra near the loop before cutting (off only to measure what refinement buys).
  bool refine = true;
  /// Target longest edge near the loop, as a multiple of the cutting radius.
  double target_edge_per_radius = 2.0;
  /// Refinement rounds per collision step at most (each halves the edges it reaches).
  int max_refinement_rounds = 1;
  /// Tetrahedra one collision step splits at most, closures included: a fresh stroke into coarse
  /// tissue marks hundreds at once, and with their closures that is tens of milliseconds of edits
  /// (about 20 us each, and as much again to replay them on the core's other copy). Past it, the marked
  /// ones nearest where the path starts are kept (halving until the plan fits); the rest lie where
  /// the next step's path begins, which marks them again.
  std::size_t max_refined_per_step = 128;
  /// Regular 1:8 splits a tetrahedron of the model may go through at most (closures' children are
  /// never split again).
  int max_refinement_levels = 2;
  /// The urethral channel's axis: faces of the initial surface facing it are the channel wall; the
  /// rest are the gland's outer surface, which a cut must not open (a perforation).
  Vec3 channel_origin{0.0};
  Vec3 channel_direction{0.0, 0.0, 1.0};
  /// Perforation sites kept (the count goes on past it).
  std::size_t max_perforation_sites = 64;
  /// Once dead springs (no tetrahedron left around their edge) pass this fraction of all springs,
  /// the first collision step with the pedal up compacts them away (MassSpringTissue::compact_springs):
  /// resection then leaves the physics step no dearer than the tissue that remains.
  double compact_dead_spring_fraction = 0.1;
  /// The candidate search's skin (Resection's skin list): larger keeps the list valid for more
  /// steps but makes it longer; 0 searches afresh every step (the same candidates, slower).
  double candidate_skin_m = 0.002;
};

/// Regions index arrays by their enum value (kCapsule = 1, kAdenoma = 2); slot 0 is unused.
using RegionVolumes = std::array<double, 3>;

/// Running totals of a resection.
struct ResectionStats {
  RegionVolumes initial_m3{};  ///< rest volume at the start
  RegionVolumes removed_m3{};  ///< everything that left: cut by the loop, hanging, chips
  RegionVolumes chip_m3{};     ///< the part that left as chips (hanging groups included)
  std::int64_t removed_tetrahedra = 0;
  std::int64_t chips = 0;  ///< pieces cut free (components holding no anchor); hanging debris goes with their mass, uncounted
  std::int64_t cuts = 0;          ///< strokes (pedal presses) that removed tissue
  std::int64_t perforations = 0;  ///< strokes that opened the outer surface
  std::vector<Vec3> perforation_sites;  ///< where each perforation first opened it (world, metres)
  std::int64_t sphincter_zone_violations = 0;  ///< strokes that removed tissue with the loop distal to the verumontanum
  double sphincter_zone_cut_s = 0.0;           ///< time removing tissue distal to the verumontanum
  double loop_on_idle_s = 0.0;                 ///< time with the pedal down and nothing removed
  std::int64_t refined_tetrahedra = 0;         ///< tetrahedra split by refinement (1:8 and closures)
  std::int64_t refusals = 0;                   ///< edits refused for want of reserved capacity
  std::int64_t spring_compactions = 0;         ///< dead springs dropped (with the pedal up)
};

/// What one collision step's cut did.
struct ResectionStep {
  std::int32_t cut_tetrahedra = 0;  ///< removed by the loop
  std::int32_t hanging_tetrahedra = 0;
  std::int32_t chip_tetrahedra = 0;
  std::int32_t refined_tetrahedra = 0;
  bool perforated = false;
  double removed_m3 = 0.0;
};

/// Rest volume of a tissue's live tetrahedra by region, summed afresh (for checks, O(tetrahedra)).
RegionVolumes remaining_m3(const MassSpringTissue& tissue);

class Resection {
 public:
  /// Reserves every scratch array for the tissue's capacities.
  Resection(MassSpringTissue& tissue, const ResectionConfig& config = {});

  /// One collision step of `period_s`. `sweep` is the wire's swept volume when the pedal is down and
  /// the loop out of the sheath (null otherwise); `pedal_down` alone counts idle time; `distal`: the
  /// loop is distal to the verumontanum. Call while nothing else uses the bound tissue (the core's
  /// collision job, on the copy the physics is not stepping).
  ResectionStep step(const SweptVolume* sweep, bool pedal_down, bool distal, double period_s);

  /// Edits `tissue` from now on: the core's other copy of the tissue, holding the same topology as the
  /// one edited so far (MassSpringTissue::replay brings it there).
  void bind(MassSpringTissue& tissue) { tissue_ = &tissue; }
  const ResectionStats& stats() const { return stats_; }
  /// How many times the candidate search's skin list was built (each a search over the nodes).
  std::int64_t candidate_list_builds() const { return near_builds_; }
  const ResectionConfig& config() const { return config_; }
  /// Rest volume of the live tetrahedra by region, summed afresh (for checks, O(tetrahedra)).
  RegionVolumes remaining_m3() const;
  /// Whether node n lies on the gland's outer surface (not the channel wall).
  bool outer_node(std::uint32_t n) const { return outer_node_[n] != 0; }

 private:
  void gather_candidates(const SweptVolume& sweep);
  /// The node-by-node search: every live slot whose centroid may be within `reach` more than the
  /// candidates' own reach of the path, into `out` (unsorted).
  void search_near(const SweptVolume& sweep, double extra, std::vector<std::uint32_t>& out);
  int refine_near(const SweptVolume& sweep);
  /// Cuts marked_ down to its `keep` tetrahedra nearest where the path starts.
  void keep_nearest_the_start(const SweptVolume& sweep, std::size_t keep);
  /// Drops from `slots` (this cut's tetrahedra) those the tissue's surface does not reach through
  /// faces of the others: a cut never leaves a closed void inside the tissue.
  void keep_reachable_from_surface(std::vector<std::uint32_t>& slots);
  /// Removes `slots` through the tissue, accounting them; `chip` adds them to the chips' volume.
  void remove(std::vector<std::uint32_t>& slots, bool chip, ResectionStep& out);
  /// Removes tetrahedra hanging by an edge or a vertex around the nodes of `removed` until none is.
  void remove_hanging(ResectionStep& out);
  /// Groups of the star (tetrahedra in `star_`) connected through faces holding `a` (and `b` when
  /// b != kNoNode); returns the group count and leaves each member's group in group_.
  int star_groups(std::uint32_t a, std::uint32_t b);
  bool vertex_fan_is_disk(std::uint32_t v);
  /// Removes chips grown from seeds_; returns whether there was any.
  bool remove_chips(ResectionStep& out);
  Vec3 centroid(std::uint32_t t) const;
  double longest_rest_edge(std::uint32_t t) const;
  /// Renews slot_longest_ for slots a refinement added and node_reach_ for every node they hold
  /// (which includes every node of the slots it removed: children keep their parents' corners).
  void note_refinement(std::span<const std::uint32_t> added_slots);
  std::uint32_t next_stamp();
  /// Zeroes every slot and node stamp (none is current any more).
  void restart_stamps();

  MassSpringTissue* tissue_;
  ResectionConfig config_;
  TetRefiner refiner_;
  ResectionStats stats_;
  std::vector<std::uint8_t> outer_node_;  // per node (capacity)
  // The candidate search's margins, kept for live slots and nodes as edits go: each slot's longest
  // rest edge, and each node's longest rest edge over the slots around it.
  // The candidate search keeps a skin list (as molecular dynamics keeps Verlet lists): the slots
  // whose centroid was within the skin (ResectionConfig::candidate_skin_m) more than the candidates' reach of the path when it was built.
  // While the wire's samples have moved less than the skin since, a step reads the list, plus the
  // stars of the nodes that moved further than what the skin has left (a flap of cut tissue); when
  // the wire has used up the skin, too many nodes moved, or a stroke starts, it is built afresh.
  static constexpr std::size_t kMaxMovedNodes = 512;
  std::vector<std::uint32_t> near_;  // slots (unsorted; may hold dead or reused ones: filtered)
  SweptVolume near_sweep_;           // the path it was built for
  std::vector<Vec3> near_positions_;  // the nodes' positions then (nodes made since hold only listed slots)
  std::vector<std::uint32_t> moved_nodes_;
  bool near_valid_ = false;
  std::int64_t near_builds_ = 0;
  std::vector<double> slot_longest_;  // per slot (capacity)
  std::vector<double> node_reach_;    // per node (capacity)
  // The chip search's guide: each node's rest path length along edges to the nearest anchored node
  // at the start (a midpoint takes its parents' mean), so a held component shows itself after a
  // short walk outward instead of a flood.
  std::vector<double> anchor_distance_;  // per node (capacity)
  std::vector<std::pair<double, std::uint32_t>> frontier_;  // best-first heap: (distance, slot)
  std::vector<std::pair<double, std::uint32_t>> by_distance_;  // refine_near's cap: (distance to the start, slot)
  // Stroke state.
  bool in_stroke_ = false, stroke_cut_ = false, stroke_perforated_ = false, stroke_distal_ = false;
  // Scratch, reserved for the capacities.
  std::vector<std::uint32_t> candidates_, marked_, removing_, removed_nodes_, queue_, star_, next_nodes_;
  std::vector<std::uint64_t> removed_edges_;
  std::vector<std::int32_t> group_;
  std::vector<std::int32_t> group_size_;
  std::vector<std::uint32_t> slot_stamp_, node_stamp_, seeds_;
  std::vector<std::uint8_t> slot_level_, slot_closure_, child_count_, child_info_;  // per slot: refinement history
  std::vector<std::array<std::uint32_t, 2>> fan_edges_;
  std::uint32_t stamp_ = 0;
};

}  // namespace resecto
