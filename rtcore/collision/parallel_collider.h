// One collision query on two threads. The tissue tree's top is cut into a few dozen subtrees; the
// caller's thread and a helper each run a Collider of their own and claim the subtrees from a shared
// counter, whole (walk and exact tests), until none is left; their sorted pairs are merged. A rigid
// tool's pairs are spread over the gland along the whole sheath, so the claims even out the work
// without a schedule worked out in advance. Which thread ran which subtree changes no pair.
// The helper is a LoopHelper: called in for each query, it spins between queries that come less
// than a few milliseconds apart, so a query of a few hundred microseconds does not wait tens of them
// for a sleeping thread to wake, and a helper that comes late finds its share already taken.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "rtcore/collision/collide.h"
#include "rtcore/concurrency/loop_helper.h"

namespace resecto {

class ParallelCollider {
 public:
  /// `threads`: 1 runs every query on the caller's thread; 2 adds a helper thread that shares it.
  explicit ParallelCollider(int threads = 2);
  ParallelCollider(const ParallelCollider&) = delete;
  ParallelCollider& operator=(const ParallelCollider&) = delete;

  int threads() const { return helper_ ? 2 : 1; }
  /// Collider::set_method for both threads' colliders.
  void set_method(CollisionMethod method);
  /// Collider::reserve for each thread's share (each may find every pair).
  void reserve(std::int32_t max_pairs, std::int32_t max_tested_pairs);
  /// Builds the tool's field once, for both threads (Collider::prepare_tool).
  void prepare_tool(const TriangleMesh& tool);

  /// Collider::collide's pairs: sorted by (tissue, tool), each once. False on overflow.
  bool collide(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree, const TriangleMesh& tool,
               const RigidPose& tool_pose);
  /// Collider::collide_sequence's pairs for consecutive poses, each thread keeping the front of its
  /// own fixed half of the subtrees (alternate ones, so both halves span the gland). False on overflow.
  bool collide_sequence(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree, const TriangleMesh& tool,
                        const RigidPose& tool_pose, double tissue_travel_m = 0.0);
  /// Lets the helper sleep now rather than spin for the next query (it goes by itself a few
  /// milliseconds after the last one): for a caller that does other timed work before the next.
  void release_helper() {
    if (helper_) helper_->send_home();
  }
  /// Forgets both threads' fronts (Collider::reset_sequence).
  void reset_sequence();
  std::span<const TrianglePair> pairs() const { return {pairs_.data(), pair_count_}; }
  /// Both threads' work counters, summed.
  const CollisionStats& stats() const { return stats_; }

 private:
  /// The nodes kSplitDepth below the root (or leaves above it), depth first: the claims.
  void split(const SphereTree& tissue_tree);
  void run_share(std::uint32_t share);
  /// Runs both shares (the helper's on its thread, or both here should it not come in time) and
  /// merges their pairs.
  bool run_shares();

  static constexpr int kSplitDepth = 6;  // up to 64 subtrees: far more than two threads need to even out
  Collider colliders_[2];
  std::vector<std::int32_t> starts_;
  std::vector<std::int32_t> halves_[2];  // a sequence's: each thread's fixed subtrees
  struct Pending {
    std::int32_t node, depth;
  };
  std::vector<Pending> walk_;  // split()'s: at most one pending node per level and one more
  std::atomic<std::uint32_t> next_{0};
  // The query the helper shares, written before its launch.
  struct Query {
    const SphereTree* tissue_tree = nullptr;
    const TriangleMesh* tissue = nullptr;
    const SphereTree* tool_tree = nullptr;
    const TriangleMesh* tool = nullptr;
    RigidPose pose;
    bool sequence = false;
    double tissue_travel_m = 0.0;
  } query_;
  bool share_ok_[2] = {true, true};
  std::vector<TrianglePair> pairs_;
  std::size_t pair_count_ = 0;
  CollisionStats stats_;
  std::unique_ptr<LoopHelper> helper_;  // last: its thread starts once the rest exists
};

}  // namespace resecto
