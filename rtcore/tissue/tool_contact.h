// Penalty contact between the tissue and the kinematic tool parts (sheath, loop): candidate pairs
// found at the 60 Hz collision step (the tissue's sphere tree queried against each rigid part's
// proximity grid and vertex clusters), penalty forces with damping evaluated on those pairs at every
// physics substep, and the reaction on the tool.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "rtcore/collision/sphere_tree.h"
#include "rtcore/geometry/box_columns.h"
#include "rtcore/geometry/rigid_pose.h"
#include "rtcore/mesh/triangle_mesh.h"
#include "rtcore/collision/tool_proximity_grid.h"

namespace resecto {

/// Total force and torque the tissue applies to the tool in one substep (torque about the origin of
/// each part's tool frame, i.e. the sheath tip; all parts share that frame).
struct ToolReaction {
  Vec3 force_n{0.0};
  Vec3 torque_nm{0.0};
};

/// Capacities fixed at start; exceeding one sets `overflowed` and drops pairs instead of allocating.
struct ToolContactCapacity {
  std::int32_t max_tissue_nodes = 8192;    ///< tissue nodes near a tool part
  std::int32_t max_tool_vertices = 4096;   ///< tool vertices near the tissue
  std::int32_t max_pair_entries = 262144;  ///< candidate (point, triangle) pairs in all
};

/// What one collision step found, for the profiler and the tests.
struct ToolContactStats {
  std::int32_t tissue_leaves = 0;  ///< tissue leaves that reached a part's grid, over all parts
  std::int32_t tool_clusters = 0;  ///< tool vertex clusters that found tissue faces near them, over all parts
  std::int32_t tissue_nodes = 0;   ///< candidate tissue nodes
  std::int32_t tool_vertices = 0;  ///< candidate tool vertices
  std::int32_t pair_entries = 0;
  std::int32_t pair_tests = 0;     ///< (point, face) distances the search measured to keep pair_entries
  std::int32_t penetrating = 0;    ///< points that pushed in the last substep
  bool overflowed = false;
};

/// The tool side of contact: the rigid parts, their proximity grids and vertex clusters, their poses.
class ToolContacts {
 public:
  /// Proof that the brute-force test would find a point outside its candidate triangles, so that it
  /// takes no force: at `at` (tool frame for a tissue node, world for a tool vertex) it was at least
  /// `radius` from every one, with no candidate able to become its nearest and have it behind its
  /// plane within that radius, and the tissue had travelled `tissue_travel` by then. Distances and
  /// heights change no faster than the point and the triangles' corners move, so while the point has
  /// moved less than the radius minus the tissue's travel since, the test's answer is still
  /// "outside". Issued by the search only: a tested point is tested until the next search.
  /// radius 0: no proof, test the point.
  struct Clearance {
    Vec3 at{0.0};
    double radius = 0.0;
    double tissue_travel = 0.0;
    /// The tissue's travel since beyond which the proof lapses whatever the radius: a moving face
    /// the point may come nearest to could have turned its plane too far toward the point.
    double travel_cap = std::numeric_limits<double>::infinity();
    /// Whether the proof still holds for the point now at `point`, the tissue's travel now being
    /// `tissue_travel_now`.
    bool holds(const Vec3& point, double tissue_travel_now) const;
  };

  /// `margin_m`: how far outside the tool a point may be and still become a candidate; it must
  /// exceed what tool and tissue move in one collision step.
  explicit ToolContacts(double margin_m = 0.0015, const ToolContactCapacity& capacity = {});

  /// Adds a rigid part given in the tool frame; returns its index. Call before the first step.
  int add_part(const TriangleMesh& mesh_in_tool_frame);
  int part_count() const { return static_cast<int>(parts_.size()); }
  /// Sets where a part is for the coming physics step; the previous pose gives the tool's velocity.
  void set_pose(int part, const RigidPose& pose);
  /// Places a part without motion (both poses), e.g. at start.
  void reset_pose(int part, const RigidPose& pose);
  /// Takes a part out of (or back into) contact, e.g. the loop when it is not modelled.
  void set_enabled(int part, bool enabled) { parts_[static_cast<std::size_t>(part)].enabled = enabled; }
  const RigidPose& pose(int part) const { return parts_[static_cast<std::size_t>(part)].pose; }
  /// How far outside the tool a point may be and still become a candidate.
  double margin_m() const { return margin_m_; }

  // The 60 Hz collision step in three parts, so the search can run on another thread while physics
  // steps go on with the candidates already published (the core's collision pipeline):
  /// Takes the parts' current poses and enabled flags as the ones the next search uses, and the
  /// tissue's travel (MassSpringTissue::travel_m) at the positions it will search. Call on the
  /// thread that sets poses, while no search runs.
  void latch_query_poses(double tissue_travel_m);
  /// Replaces a part's latched pose with where the search should look for it instead (e.g. where the
  /// part is expected to be while the candidates are in use). Same rules as latch_query_poses().
  void set_query_pose(int part, const RigidPose& pose) { parts_[static_cast<std::size_t>(part)].query_pose = pose; }
  /// Where the part is expected to be when the search's candidates are published (the latched pose
  /// unless set): the search certifies each point's clearance there rather than at the query pose,
  /// so that the first physics step on the new candidates finds most certificates holding. Any pose
  /// gives sound certificates: each ball is cut to the margin less the distance from where the point
  /// was searched, so it is clear of every face, candidate or not; a good guess only makes more of them
  /// hold. Same rules as latch_query_poses().
  void set_certify_pose(int part, const RigidPose& pose) { parts_[static_cast<std::size_t>(part)].certify_pose = pose; }
  /// Finds, for each part at its latched pose, the tissue surface nodes within the margin of it and
  /// the part's vertices within the margin of the tissue, each with every triangle of the other side
  /// within the margin, from the tissue surface tree (already refitted to `surface`'s positions), into
  /// a back buffer. Touches nothing evaluate_forces() or set_pose() use, so
  /// it may run concurrently with them; never with latch_query_poses() or publish_candidates().
  /// Each point it keeps comes with its clearance certificate at the searched positions.
  void search_candidates(const SphereTree& tissue_tree, const TriangleMesh& surface);
  /// Makes the last search's candidates the ones evaluate_forces() uses (a swap: no allocation).
  void publish_candidates();
  /// How far the latched query poses have moved the tool from where the published candidates were
  /// searched: the largest displacement of an enabled part's vertex between the two. Infinite when
  /// nothing was published, a part was enabled or disabled since, or a topology edit voided the
  /// candidates. Same threading rules as search_candidates().
  double tool_shift_since_search() const;

  /// One substep's penalty forces on the candidate pairs at positions x, velocities v, in two
  /// halves so that the first can run beside the spring pass (it reads only positions and
  /// velocities): evaluate_forces() finds them and keeps each node's share in order, apply_forces()
  /// adds the shares to `force` and to the per-node bounds of the contact stiffness and damping the
  /// integrator needs, in that order. `tissue_travel_m` bounds how far any tissue node has moved since
  /// the tissue was created (a running sum of each step's largest node displacement); it lets a point
  /// found clear of the other surface skip its tests until the two could have met. Returns the
  /// reaction on the tool.
  ToolReaction evaluate_forces(std::span<const Vec3> x, std::span<const Vec3> v, const std::vector<Triangle>& surface_triangles,
                               double stiffness_n_m, double damping_ns_m, double h_s, double tissue_travel_m);
  void apply_forces(std::span<Vec3> force, std::span<double> stiffness_bound, std::span<double> damping_bound) const;

  /// Whether evaluate_forces() may skip points whose clearance certificate still holds, and stop a point's
  /// scan at the first face its search distance proves cannot be the nearest (on by default). Off,
  /// every candidate point is tested against every one of its faces at every step: the brute-force
  /// reference the tests and benchmarks compare against. The forces are the same either way, bit for
  /// bit, folds of the tissue's surface included (docs/commands.md, "Contact costs what is in contact").
  void set_clearance_skipping(bool enabled) { clearance_skipping_ = enabled; }

  /// After a topology edit of the tissue (resection), between physics steps with no search running:
  /// drops the published pairs whose tissue face slot changed (`changed_face[s] != 0`: removed or
  /// reused) and the candidate tissue nodes that were orphaned (`dead_node[n] != 0`), and voids every
  /// clearance certificate, since the surface they measured against is not the one now. New faces
  /// become candidates at the next search.
  void invalidate_tissue(std::span<const std::uint8_t> changed_face, std::span<const std::uint8_t> dead_node);
  /// Sizes the search's per-node and per-face stamps for a tissue that may grow to these counts, so
  /// a growing surface does not allocate at a search.
  void reserve_tissue(std::size_t max_nodes, std::size_t max_faces);
  const ToolContactStats& stats() const { return stats_; }
  /// One published candidate point: a tissue node (against part `part`'s faces) or a tool vertex of
  /// part `part` (against tissue faces), with its candidate faces nearest first.
  struct CandidatePoint {
    std::uint32_t point;
    int part;
    std::span<const std::uint32_t> faces;
  };
  std::size_t node_candidate_count() const { return node_count_; }
  CandidatePoint node_candidate(std::size_t i) const { return view(node_candidates_[i]); }
  std::size_t vertex_candidate_count() const { return vertex_count_; }
  CandidatePoint vertex_candidate(std::size_t i) const { return view(vertex_candidates_[i]); }
  /// For the tissue's second copy taking over (MassSpringTissue::adopt_motion): the parts' poses and
  /// enabled flags, the last step's statistics and the point counters become `front`'s.
  void adopt_motion(const ToolContacts& front);
  /// The parts' latched query poses and flags and the latched tissue travel become `front`'s, so a
  /// search here looks where the front's would (call while no search runs on either).
  void copy_query_state(const ToolContacts& front);
  /// Point evaluations evaluate_forces() ran and skipped on its certificates, since construction.
  std::int64_t points_evaluated() const { return points_evaluated_; }
  std::int64_t points_skipped() const { return points_skipped_; }

 private:
  /// Vertices of a part near one another, searched against the tissue together: the tissue faces near
  /// the cluster are picked once for all of them. Vertices [first, first + count) of cluster_vertices.
  static constexpr double kClusterMargins = 4.0;  ///< the largest radius of a cluster's bound, in margins
  struct VertexCluster {
    Sphere bound;  // tool frame
    std::uint32_t first = 0, count = 0;
  };
  struct Part {
    TriangleMesh mesh;          // tool frame
    std::vector<Vec3> face_normals;  // unit, tool frame
    std::vector<Sphere> triangle_spheres;  // per face, tool frame: prunes the closest-point tests
    std::vector<std::pair<Vec3, Vec3>> face_boxes;  // per face, tool frame: its bounding box (low, high)
    ToolProximityGrid grid;     // the faces within the margin of a point of the tool frame
    std::vector<VertexCluster> clusters;
    std::vector<std::uint32_t> cluster_vertices;
    RigidPose pose, previous_pose;
    bool enabled = true;
    RigidPose query_pose;  // latched for the search (the search's thread reads only these)
    bool query_enabled = true;
    RigidPose certify_pose;  // where the search certifies its points' clearance (set_certify_pose)
    RigidPose published_pose;  // the query pose the published candidates were searched at
    bool published_enabled = false;
  };
  /// A point with its candidate triangles: entries [first, first + count) of pair_triangles_.
  struct PointCandidates {
    std::uint32_t point;  // tissue node, or tool vertex
    std::uint16_t part;
    std::uint32_t first;
    std::uint32_t count;
    Vec3 searched_at;  // where the search found it (tool frame for a tissue node, world for a tool vertex)
  };
  /// A tissue node at a corner of a tool vertex's candidate face, and where the search saw it.
  struct SearchedCorner {
    std::uint32_t node;
    Vec3 at;
  };
  /// A face within the margin of a point, with the bits of its squared distance (non-negative, so
  /// they order as the distance does).
  struct KeptFace {
    std::uint64_t distance2_bits;
    std::uint32_t face;
  };
  /// A search's result, built in the back buffer and swapped in by publish_candidates().
  struct CandidateSet {
    std::vector<PointCandidates> nodes, vertices;
    std::vector<std::uint32_t> pair_triangles;
    std::vector<double> pair_distance;  // per pair, its face's distance from the point at the search
    std::vector<KeptFace> kept;  // scratch: a point's kept faces with their distance², for the order
    std::vector<Clearance> node_clearance, vertex_clearance;  // per point, at the searched positions
    std::vector<SearchedCorner> corners;  // every corner of the tool vertices' candidate faces, each once
    std::size_t node_count = 0, vertex_count = 0, pair_count = 0, corner_count = 0;
    ToolContactStats stats;
    std::vector<std::pair<PointCandidates, Clearance>> sorting;  // scratch of order_points()
  };
  CandidatePoint view(const PointCandidates& pc) const { return {pc.point, pc.part, {pair_triangles_.data() + pc.first, pc.count}}; }
  /// Groups a part's vertices into clusters (add_part).
  void build_vertex_clusters(Part& part) const;
  /// Puts the search's first `count` points in (part, point) order, with their certificates.
  void order_points(std::vector<PointCandidates>& points, std::vector<Clearance>& clearance, std::size_t count);
  /// Fills part_leaves_ with the tissue tree's leaves that reach the part's grid box at its query
  /// pose, and near_nodes_ with their corners, each once.
  void gather_part_leaves(const Part& part, const SphereTree& tissue_tree, const TriangleMesh& surface);
  /// Fills near_triangles_ and near_boxes_ with the triangles of part_leaves_ whose leaf sphere is
  /// within `radius` of `point`, each once, and their boxes.
  void select_triangles(const Vec3& point, double radius, const TriangleMesh& surface);
  /// The tissue nodes of near_nodes_ within the margin of the part, with their candidate faces.
  void search_tissue_nodes(std::uint16_t part_index, const TriangleMesh& surface);
  /// The part's vertices within the margin of the tissue, with their candidate tissue faces
  /// (from part_leaves_: every face within the margin of the part reaches its grid box).
  void search_tool_vertices(std::uint16_t part_index, const TriangleMesh& surface);
  bool push_pair(std::uint32_t triangle);
  /// Lists the corners of the tool vertices' candidate faces with their searched positions.
  void collect_searched_corners(const TriangleMesh& surface);
  /// The largest distance any listed corner has moved from where the search saw it (rounded up).
  double corners_moved(std::span<const Vec3> x) const;
  /// Drops the pairs from `first` on whose triangle is further than the margin from `p`, and orders
  /// the rest nearest first (ties by triangle index), so the closest-face search's exact prune
  /// discards most of them after the first test.
  void keep_within_margin(std::uint32_t first, const Vec3& p, const std::vector<Vec3>& positions,
                          const std::vector<Triangle>& triangles);

  double margin_m_;
  ToolContactCapacity capacity_;
  std::vector<Part> parts_;
  // The published candidates, which evaluate_forces() reads.
  std::vector<PointCandidates> node_candidates_;    // tissue node against tool triangles
  std::vector<PointCandidates> vertex_candidates_;  // tool vertex against tissue triangles
  std::vector<std::uint32_t> pair_triangles_;
  // Per pair, its face's distance at the search: a face further than the best so far by more than
  // the motion since cannot be the nearest, and the faces are nearest first, so a point's scan stops
  // there (exact: the same face wins as when every face is tested).
  std::vector<double> pair_distance_;
  double candidates_travel_m_ = 0.0;  // the tissue's travel at the published search (its latched one)
  bool distances_valid_ = false;      // false until a publish, and from a topology edit until the next
  std::size_t node_count_ = 0, vertex_count_ = 0, pair_count_ = 0;
  // The published search's corners of the tool vertices' candidate faces: how far they have moved
  // bounds how much nearer a vertex's faces can have come since the search.
  std::vector<SearchedCorner> searched_corners_;
  std::size_t corner_count_ = 0;
  // Per published candidate point, its clearance certificate (the search's).
  std::vector<Clearance> node_clearance_, vertex_clearance_;
  // evaluate_forces()'s result: each push's share of a node's force and bounds, in the order made.
  struct NodeShare {
    std::uint32_t node;
    Vec3 force;
    double stiffness, damping;
  };
  std::vector<NodeShare> shares_;  // room for a share per candidate node and three per candidate vertex
  std::size_t share_count_ = 0;
  double query_tissue_travel_m_ = 0.0;  // latched with the query poses
  bool clearance_skipping_ = true;
  std::int64_t points_evaluated_ = 0, points_skipped_ = 0;
  // The search's side: its result and its scratch (stamps, stack), never read by evaluate_forces().
  CandidateSet search_;
  std::vector<std::uint32_t> node_stamp_, tissue_triangle_stamp_;
  std::uint32_t stamp_ = 0;
  std::vector<std::int32_t> stack_;
  /// A tissue leaf near a part: its sphere and triangle.
  struct NearLeaf {
    Sphere sphere;
    std::uint32_t triangle;
  };
  std::vector<NearLeaf> part_leaves_;  // gather_part_leaves()'s
  /// A tissue node at a corner of a leaf near a part, and where it is in the part's frame.
  struct NearNode {
    std::uint32_t node;
    Vec3 in_part;
  };
  std::vector<NearNode> near_nodes_;  // gather_part_leaves()'s
  std::vector<std::uint64_t> near_node_bits_;  // gather_part_leaves()'s scratch: a bit per tissue node, all clear between calls
  std::vector<std::uint32_t> near_triangles_;  // select_triangles()'s result
  BoxColumns near_boxes_;  // per face of near_triangles_, its box at the searched positions
  std::vector<std::uint32_t> near_indices_;  // a vertex's boxes within the margin (BoxColumns::within)
  ToolContactStats stats_;
};

}  // namespace resecto
