#include "rtcore/collision/parallel_collider.h"

#include <algorithm>

namespace resecto {

ParallelCollider::ParallelCollider(int threads) {
  starts_.reserve(std::size_t{1} << kSplitDepth);
  for (auto& half : halves_) half.reserve(starts_.capacity());
  walk_.reserve(2 * kSplitDepth + 2);
  if (threads >= 2) helper_ = std::make_unique<LoopHelper>();
}

void ParallelCollider::set_method(CollisionMethod method) {
  for (Collider& c : colliders_) c.set_method(method);
}

void ParallelCollider::reserve(std::int32_t max_pairs, std::int32_t max_tested_pairs) {
  for (Collider& c : colliders_) c.reserve(max_pairs, max_tested_pairs);
  pairs_.resize(2 * static_cast<std::size_t>(std::max(max_pairs, 1)));
}

void ParallelCollider::prepare_tool(const TriangleMesh& tool) {
  colliders_[0].prepare_tool(tool);
  colliders_[1].share_tool(colliders_[0]);
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
                                                            halves_[share])
                                : collider.collide_claimed(*q.tissue_tree, *q.tissue, *q.tool_tree, *q.tool, q.pose, starts_, next_);
}

bool ParallelCollider::collide(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree, const TriangleMesh& tool,
                               const RigidPose& tool_pose) {
  split(tissue_tree);
  query_ = {&tissue_tree, &tissue, &tool_tree, &tool, tool_pose, false, 0.0};
  next_.store(0, std::memory_order_relaxed);
  return run_shares();
}

bool ParallelCollider::collide_sequence(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
                                        const TriangleMesh& tool, const RigidPose& tool_pose, double tissue_travel_m) {
  split(tissue_tree);
  // Alternate subtrees of the depth-first order: neighbours in the gland go to both threads, so a
  // tool pressing anywhere gives both work. One thread alone runs them all.
  for (auto& half : halves_) half.clear();
  for (std::size_t k = 0; k < starts_.size(); ++k) halves_[helper_ ? k % 2 : 0].push_back(starts_[k]);
  query_ = {&tissue_tree, &tissue, &tool_tree, &tool, tool_pose, true, tissue_travel_m};
  return run_shares();
}

bool ParallelCollider::run_shares() {
  share_ok_[1] = true;
  // A sequence's second half is empty only for a tree of one node (and an empty list of starts
  // would mean the whole tree).
  const bool helper_runs = helper_ && !(query_.sequence && halves_[1].empty());
  if (helper_runs) {
    // Share k is Collider k's whichever thread claims it (a sequence's front stays with its
    // Collider), and each share is claimed once: what the query wrote above is visible to both, and
    // both shares' writes are visible here once the loop returns.
    helper_->call_in();
    auto share = [this](std::uint32_t k) { run_share(k); };
    helper_->for_each_chunk(2, share);
  } else {
    run_share(0);
  }
  // Each share is sorted and holds each pair once; a sliced tissue triangle's leaves may have gone
  // to both, so the merge drops repeats.
  const std::span<const TrianglePair> a = colliders_[0].pairs();
  const std::span<const TrianglePair> b = helper_runs ? colliders_[1].pairs() : std::span<const TrianglePair>{};
  if (pairs_.size() < a.size() + b.size()) pairs_.resize(a.size() + b.size());  // only past every reserve()d size
  const auto end = std::merge(a.begin(), a.end(), b.begin(), b.end(), pairs_.begin());
  pair_count_ = static_cast<std::size_t>(std::unique(pairs_.begin(), end) - pairs_.begin());
  stats_ = colliders_[0].stats();
  if (helper_runs) {
    const CollisionStats& h = colliders_[1].stats();
    stats_.sphere_tests += h.sphere_tests;
    stats_.front_kept += h.front_kept;
    stats_.front_renewed += h.front_renewed;
    stats_.leaf_pairs += h.leaf_pairs;
    stats_.triangle_tests += h.triangle_tests;
  }
  return share_ok_[0] && share_ok_[1];
}

}  // namespace resecto
