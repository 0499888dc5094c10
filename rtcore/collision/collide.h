// Every intersecting triangle pair between the tissue and a rigid tool. Two ways, same pairs: the
// tissue's sphere tree descended alone against the tool's precomputed field (the default: a rigid
// tool's proximity is worked out once in its own frame, so each tissue sphere is tested once rather
// than against each tool sphere), or the paper's dual descent (section 3.2, Figure 11), two sphere
// trees walked together, which also gives the colliding leaf lists L1 and L2 its penalty response
// reads. Runs in the 60 Hz core step, so a query allocates nothing.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/collision/sphere_tree.h"
#include "rtcore/collision/tool_field.h"
#include "rtcore/geometry/rigid_pose.h"

namespace resecto {

/// An intersecting pair: a tissue triangle and a tool triangle (indices into their meshes).
struct TrianglePair {
  std::uint32_t tissue = 0;
  std::uint32_t tool = 0;
  friend bool operator==(const TrianglePair&, const TrianglePair&) = default;
  friend auto operator<=>(const TrianglePair&, const TrianglePair&) = default;
};

/// How a query finds the pairs (the pairs are the same either way).
enum class CollisionMethod {
  kToolField,    ///< the tissue's tree alone against the tool's ToolField
  kDualDescent,  ///< the paper's: the tissue's and the tool's trees together
};

/// Work counters of the last query.
struct CollisionStats {
  std::int64_t sphere_tests = 0;    ///< bound tests: node pairs (dual descent) or tissue nodes (field)
  std::int64_t front_kept = 0;      ///< sequence: cached nodes or node pairs whose certificate still held
  std::int64_t front_renewed = 0;   ///< sequence: cached nodes or node pairs walked again
  std::int64_t leaf_pairs = 0;      ///< leaf pairs whose spheres met (field: tissue leaf, near tool triangle)
  std::int64_t triangle_tests = 0;  ///< exact triangle tests (after the box prefilter)
};

/// Runs the dual descent. Holds every buffer a query needs; after reserve() (or the first queries
/// on trees of a given size) a query allocates nothing. A query whose pairs exceed the reserved
/// capacity sets overflowed() and returns false rather than allocating.
class Collider {
 public:
  Collider() { reserve(4096, 16384); }

  /// Room for `max_pairs` intersecting pairs and `max_tested_pairs` distinct triangle pairs tested.
  void reserve(std::int32_t max_pairs, std::int32_t max_tested_pairs);
  /// Room for tissue trees of up to `max_nodes` nodes (a tree that resection grows), so a query on
  /// one allocates nothing.
  void reserve_tissue_nodes(std::int32_t max_nodes);

  /// Which way queries go (kToolField unless changed).
  void set_method(CollisionMethod method) { method_ = method; front_valid_ = false; }
  CollisionMethod method() const { return method_; }

  /// Builds the tool's field for the field method, off the query path. A query checks the tool's
  /// fingerprint (a hash of its vertices and triangles, about a microsecond for the resectoscope)
  /// and builds the field first for a tool it has not seen.
  void prepare_tool(const TriangleMesh& tool);

  /// Finds every pair of intersecting closed triangles between the tissue and the tool placed at
  /// `tool_pose` (the tool tree is in tool coordinates; its spheres move with the pose, never
  /// refitted). Pairs come out sorted by (tissue, tool), each once. False on overflow.
  bool collide(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
               const TriangleMesh& tool, const RigidPose& tool_pose);

  /// collide() over part of the tissue tree, so that several Colliders, one per thread, share a
  /// query: the subtrees under the nodes of `starts`, each run by whichever sharer claims its index
  /// from `next` first (fetch_add; none is left once it reaches starts.size()). The pairs are those
  /// of the subtrees this one ran, sorted, each once; the union over the sharers is collide()'s,
  /// whoever ran which. The same for the leaf lists. False on overflow.
  bool collide_claimed(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree, const TriangleMesh& tool,
                       const RigidPose& tool_pose, std::span<const std::int32_t> starts, std::atomic<std::uint32_t>& next);
  /// Takes the tool field `prepared` built (prepare_tool) rather than building its own.
  void share_tool(const Collider& prepared) {
    field_ = prepared.field_;
    field_tool_ = prepared.field_tool_;
  }

  /// The same pairs as collide() for consecutive poses of one tool against one tissue tree, reusing
  /// the previous call's work (temporal coherence). Every node pair (the field method: every tissue
  /// node) where the last descent stopped is kept with a certificate: the bounds were `gap` apart
  /// (the field method: the node's sphere was `gap` clear of the tool's surface), so nothing can meet
  /// until the tool and the tissue together have moved `gap`. The tool's motion is bounded exactly
  /// (its vertices' largest displacement between calls, summed), the tissue's by `tissue_travel_m`,
  /// a running bound on how far any tissue point has moved (0 for a static tissue); only pairs whose
  /// certificate ran out, and leaf pairs whose bounds met, are walked again. Starts afresh when
  /// either tree's structure changed or the cached pairs grew past twice a fresh descent's. The
  /// leaf lists are those of the walked pairs (a subset of collide()'s); the pairs are the same.
  /// `starts` (empty: the root) limits the sequence to the subtrees under those tissue nodes, the
  /// same ones every call, as collide_claimed() limits a query: how two threads share a sequence.
  bool collide_sequence(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
                        const TriangleMesh& tool, const RigidPose& tool_pose, double tissue_travel_m = 0.0,
                        std::span<const std::int32_t> starts = {});
  /// Forgets the cached front: the next collide_sequence() descends from the roots.
  void reset_sequence() { front_valid_ = false; }
  /// Room for this many cached node pairs (a sequence that needs more starts afresh each call).
  void reserve_front(std::int32_t max_front);

  /// Whether the dual descent also tests each node's slab (the default), or spheres alone as the
  /// paper does. The pairs are the same either way; the leaf lists are shorter with the slabs. The
  /// field method reads the tissue's spheres only.
  void set_slabs(bool enabled) { slabs_wanted_ = enabled; }

  /// Whether queries find the intersecting triangle pairs (the default) or only the leaf lists, as
  /// the contact response needs: that skips every exact triangle test.
  void set_pairs_wanted(bool wanted) { pairs_wanted_ = wanted; }
  std::span<const TrianglePair> pairs() const { return {pairs_.data(), pair_count_}; }
  /// L1: the tissue leaves whose spheres met a tool leaf sphere (the field method: came within
  /// reach of the tool's surface), each once, in the order found.
  std::span<const std::int32_t> tissue_leaves() const { return {l1_.data(), l1_count_}; }
  /// L2: the tool leaves whose spheres met a tissue leaf sphere, each once, in the order found. The
  /// dual descent's only: the field method finds the tool's triangles without its leaves.
  std::span<const std::int32_t> tool_leaves() const { return {l2_.data(), l2_count_}; }
  bool overflowed() const { return overflowed_; }
  const CollisionStats& stats() const { return stats_; }

 private:
  struct NodePair {
    std::int32_t tissue;
    std::int32_t tool;
  };
  void prepare(const SphereTree& tissue_tree, const SphereTree& tool_tree, const TriangleMesh& tool);
  /// Resets the per-query state and places the tool; false when either tree is empty.
  bool begin_query(const SphereTree& tissue_tree, const SphereTree& tool_tree, const TriangleMesh& tool,
                   const RigidPose& tool_pose);
  /// The bounds test of one node pair: > 0 is a lower bound on the distance between their
  /// triangles (separated), <= 0 means they may meet.
  double gap(std::int32_t tissue_node, std::int32_t tool_node) const;
  bool bounds_meet(std::int32_t tissue_node, std::int32_t tool_node, double distance2) const;
  /// Walks every node pair under `start` whose bounds meet; with kRecord, each pair where the walk
  /// stops goes to the front with its certificate.
  template <bool kRecord>
  void descend(NodePair start);
  void visit_leaves(const NodePair& pair);
  /// collide()'s walk of the subtree under tissue node `start`, its leaves' exact tests included.
  void walk_subtree(std::int32_t start);
  // The field method: the tissue's tree alone, in the tool's frame.
  Vec3 to_tool(const Vec3& world) const { return inverse_rotation_ * (world - pose_.translation); }
  double field_gap(std::int32_t tissue_node) const;
  template <bool kRecord>
  void descend_field(std::int32_t start);
  void visit_field_leaf(std::int32_t leaf, const Vec3& centre, double radius);
  /// Visits the leaves the descents set aside, loading each one's data a few leaves ahead.
  void visit_field_leaves();
  void renew_front(const SphereTree& tissue_tree, const SphereTree& tool_tree);
  void record(const NodePair& pair, double expiry);
  void finish_query();
  bool first_test_of(std::uint32_t tissue_triangle, std::uint32_t tool_triangle);
  void test_triangles(const TriangleMesh& tissue, std::uint32_t a, std::uint32_t b, bool may_repeat);
  /// The exact test of tissue triangle a (corners p0, p1, p2) against tool triangle b, as brute force's.
  void exact_test(std::uint32_t a, const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint32_t b);
  void next_stamp();

  RigidPose pose_;
  CollisionMethod method_ = CollisionMethod::kToolField;
  ToolField field_;
  std::uint64_t field_tool_ = 0;  // the fingerprint of the tool the field was built for (0: none)
  glm::dmat3 inverse_rotation_{1.0};  // the field method: world to the tool's frame (with the translation)
  double inverse_scale_ = 1.0;        // bounds how much inverse_rotation_ can stretch a tissue sphere
  std::vector<std::int32_t> node_stack_;  // the field method's descent
  struct NearLeaf {
    Vec3 centre;  // in the tool's frame
    double radius;
    std::int32_t leaf;
  };
  std::vector<NearLeaf> near_leaves_;  // the leaves within reach of the tool, visited after the descent
  std::size_t near_leaf_count_ = 0;
  // The trees and meshes of the running query.
  const SphereTree* tissue_tree_ = nullptr;
  const SphereTree* tool_tree_ = nullptr;
  const TriangleMesh* tissue_mesh_ = nullptr;
  double slack_ = 0.0;
  double slab_slack_ = 0.0;
  bool slabs_wanted_ = true;
  bool slabs_ = true;  // this query: the pose is rigid enough for the tool's slabs to be moved by it
  double radius_scale_ = 1.0;  // bounds how much the pose's matrix can stretch a tool sphere
  std::uint32_t stamp_ = 0;    // per-query mark: an entry is set for this query when it equals stamp_

  // The tool placed in the world once per query (its tree is small): node spheres, vertices, and
  // each triangle's box for the exact prefilter ahead of the triangle test.
  std::vector<Sphere> tool_spheres_;
  std::vector<Slab> tool_slabs_;
  std::vector<Vec3> tool_vertices_;
  std::vector<Aabb> tool_boxes_;
  const TriangleMesh* tool_mesh_ = nullptr;
  // The tool's leaves grouped by triangle in chain order (slab 0, 1, ...), and each leaf's rank in
  // its group: a sliced tool triangle's earlier slabs are scanned nearest first.
  std::vector<std::int32_t> tool_chain_begin_;  // per tool triangle, into tool_chain_
  std::vector<std::int32_t> tool_chain_;
  std::vector<std::int32_t> tool_leaf_rank_;  // per tool node
  std::vector<std::uint32_t> l1_stamp_;
  std::vector<std::uint32_t> l2_stamp_;
  std::vector<std::int32_t> l1_;
  std::vector<std::int32_t> l2_;
  std::size_t l1_count_ = 0;
  std::size_t l2_count_ = 0;

  struct TestedSlot {
    std::uint64_t key = 0;    // (tissue triangle << 32) | tool triangle
    std::uint32_t stamp = 0;  // the query that filled the slot
  };
  std::vector<TestedSlot> tested_;  // open addressing: triangle pairs tested this query
  std::size_t tested_count_ = 0;
  std::size_t tested_window_ = 256;  // power of two, at most tested_.size()
  std::vector<TrianglePair> pairs_;
  bool pairs_wanted_ = true;
  std::size_t pair_count_ = 0;
  std::vector<NodePair> stack_;
  bool overflowed_ = false;
  CollisionStats stats_;

  // The sequence's front: node pairs where the last walk stopped, each with the travel at which
  // its certificate runs out (structure of arrays: the per-call scan reads only the expiries).
  std::vector<NodePair> front_pairs_;
  std::vector<double> front_expiry_;
  std::size_t front_count_ = 0;
  std::size_t fresh_front_count_ = 0;  // the front's size after the last fresh descent
  std::size_t pending_slot_ = 0;       // a renewed pair's slot, reused by its first successor
  bool has_pending_slot_ = false;
  bool front_overflowed_ = false;
  bool front_valid_ = false;
  double travel_ = 0.0;  // bound on the tool's and the tissue's motion since the front began
  double last_tissue_travel_ = 0.0;
  const SphereTree* front_tissue_tree_ = nullptr;
  const SphereTree* front_tool_tree_ = nullptr;
  std::uint64_t front_tissue_version_ = 0;
  std::uint64_t front_tool_version_ = 0;
  std::vector<Vec3> previous_tool_vertices_;
};

/// Every intersecting pair by testing every tissue triangle against every tool triangle (with a
/// box-overlap prefilter, exact on the coordinates), sorted: the oracle and the benchmark baseline.
std::vector<TrianglePair> collide_brute_force(const TriangleMesh& tissue, const TriangleMesh& tool,
                                              const RigidPose& tool_pose);

}  // namespace resecto
