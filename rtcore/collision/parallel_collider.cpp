#include "rtcore/collision/parallel_collider.h"

#include <algorithm>

namespace resecto {

ParallelCollider::ParallelCollider(int threads) {
  starts_.reserve(std::size_t{1} << kSplitDepth);
  for (auto& share : sequence_shares_) share.reserve(starts_.capacity());
  walk_.reserve(2 * kSplitDepth + 2);
  if (threads >= 2) helper_ = std::make_unique<LoopHelper>();
}

void ParallelCollider::set_method(CollisionMethod method) {
  for (Collider& c : colliders_) c.set_method(method);
}

void ParallelCollider::reserve(std::int32_t max_pairs, std::int32_t max_tested_pairs) {
  for (Collider& c : colliders_) c.reserve(max_pairs, max_tested_pairs);
  pairs_.resize(kSequenceShares * static_cast<std::size_t>(std::max(max_pairs, 1)));
  merged_.resize(pairs_.size());
}

void ParallelCollider::prepare_tool(const TriangleMesh& tool) {
  colliders_[0].prepare_tool(tool);
  for (std::uint32_t k = 1; k < kSequenceShares; ++k) colliders_[k].share_tool(colliders_[0]);
}

void ParallelCollider::split(const SphereTree& tissue_tree) {
  starts_.clear();
  if (tissue_tree.empty()) return;
  // Depth first, left before right, with each node's depth: a node at the split depth, or a leaf
  // above it, is a claim.
  walk_.assign(1, {tissue_tree.root(), 0});
  while (!walk_.empty()) {
    const Pending pending = walk_.back();
    walk_.pop_back();
    if (pending.depth == kSplitDepth || tissue_tree.is_leaf(pending.node)) {
      starts_.push_back(pending.node);
      continue;
    }
    const SphereTreeLinks& links = tissue_tree.links()[static_cast<std::size_t>(pending.node)];
    walk_.push_back({links.right, pending.depth + 1});
    walk_.push_back({links.left, pending.depth + 1});
  }
}

void ParallelCollider::reset_sequence() {
  for (Collider& c : colliders_) c.reset_sequence();
}

void ParallelCollider::run_share(std::uint32_t share) {
  Collider& collider = colliders_[share];
  const Query& q = query_;
  share_ok_[share] = q.sequence ? collider.collide_sequence(*q.tissue_tree, *q.tissue, *q.tool_tree, *q.tool, q.pose, q.tissue_travel_m,
                                                            sequence_shares_[share])
                                : collider.collide_claimed(*q.tissue_tree, *q.tissue, *q.tool_tree, *q.tool, q.pose, starts_, next_);
}

bool ParallelCollider::collide(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree, const TriangleMesh& tool,
                               const RigidPose& tool_pose) {
  split(tissue_tree);
  query_ = {&tissue_tree, &tissue, &tool_tree, &tool, tool_pose, false, 0.0};
  next_.store(0, std::memory_order_relaxed);
  // One share a thread, each claiming subtrees until none is left.
  share_count_ = helper_ ? 2 : 1;
  return run_shares();
}

bool ParallelCollider::collide_sequence(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
                                        const TriangleMesh& tool, const RigidPose& tool_pose, double tissue_travel_m) {
  split(tissue_tree);
  // Subtrees dealt round the shares in depth-first order: neighbours in the gland go to different
  // shares, so a tool pressing anywhere gives each work. One thread alone runs them as one share.
  // A share left empty (a tree of few subtrees) is not run; its Collider's front, if any, is
  // forgotten, as it would be for a reshaped tree.
  share_count_ = helper_ ? kSequenceShares : 1;
  for (auto& share : sequence_shares_) share.clear();
  for (std::size_t k = 0; k < starts_.size(); ++k) sequence_shares_[k % share_count_].push_back(starts_[k]);
  while (share_count_ > 1 && sequence_shares_[share_count_ - 1].empty()) colliders_[--share_count_].reset_sequence();
  query_ = {&tissue_tree, &tissue, &tool_tree, &tool, tool_pose, true, tissue_travel_m};
  return run_shares();
}

bool ParallelCollider::run_shares() {
  if (share_count_ > 1) {
    // Share k is Collider k's whichever thread claims it (a sequence's front stays with its
    // Collider), and each share is claimed once: what the query wrote above is visible to both
    // threads, and every share's writes are visible here once the loop returns.
    helper_->call_in();
    auto share = [this](std::uint32_t k) { run_share(k); };
    helper_->for_each_chunk(share_count_, share);
  } else {
    run_share(0);
  }
  // Each share is sorted and holds each pair once; a sliced tissue triangle's leaves may have gone
  // to several, so the merge drops repeats. Merged share by share, between two buffers.
  std::size_t total = 0;
  for (std::uint32_t k = 0; k < share_count_; ++k) total += colliders_[k].pairs().size();
  if (pairs_.size() < total) {  // only past every reserve()d size
    pairs_.resize(total);
    merged_.resize(total);
  }
  const std::span<const TrianglePair> first = colliders_[0].pairs();
  pair_count_ = static_cast<std::size_t>(std::copy(first.begin(), first.end(), pairs_.begin()) - pairs_.begin());
  bool ok = share_ok_[0];
  stats_ = colliders_[0].stats();
  for (std::uint32_t k = 1; k < share_count_; ++k) {
    const std::span<const TrianglePair> next = colliders_[k].pairs();
    const auto end = std::merge(pairs_.begin(), pairs_.begin() + static_cast<std::ptrdiff_t>(pair_count_), next.begin(), next.end(), merged_.begin());
    pair_count_ = static_cast<std::size_t>(std::unique(merged_.begin(), end) - merged_.begin());
    pairs_.swap(merged_);
    ok = ok && share_ok_[k];
    const CollisionStats& h = colliders_[k].stats();
    stats_.sphere_tests += h.sphere_tests;
    stats_.front_kept += h.front_kept;
    stats_.front_renewed += h.front_renewed;
    stats_.leaf_pairs += h.leaf_pairs;
    stats_.triangle_tests += h.triangle_tests;
  }
  return ok;
}

}  // namespace resecto
