#include "rtcore/collision/parallel_collider.h"

#include <algorithm>

namespace resecto {

ParallelCollider::ParallelCollider(int threads) {
  starts_.reserve(std::size_t{1} << kSplitDepth);
  walk_.reserve(2 * kSplitDepth + 2);
  if (threads >= 2) helper_ = std::make_unique<JobThread>([this] { run_share(1); });
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

void ParallelCollider::run_share(int share) {
  share_ok_[share] = colliders_[share].collide_claimed(*query_.tissue_tree, *query_.tissue, *query_.tool_tree, *query_.tool, query_.pose, starts_, next_);
}

bool ParallelCollider::collide(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree, const TriangleMesh& tool,
                               const RigidPose& tool_pose) {
  split(tissue_tree);
  query_ = {&tissue_tree, &tissue, &tool_tree, &tool, tool_pose};
  next_.store(0, std::memory_order_relaxed);
  share_ok_[1] = true;
  if (helper_) helper_->launch();  // what was written above is visible to the helper's share
  run_share(0);
  if (helper_) helper_->wait();  // and the helper's share is visible here
  // Each share is sorted and holds each pair once; a sliced tissue triangle's leaves may have gone
  // to both, so the merge drops repeats.
  const std::span<const TrianglePair> a = colliders_[0].pairs();
  const std::span<const TrianglePair> b = helper_ ? colliders_[1].pairs() : std::span<const TrianglePair>{};
  if (pairs_.size() < a.size() + b.size()) pairs_.resize(a.size() + b.size());  // only past every reserve()d size
  const auto end = std::merge(a.begin(), a.end(), b.begin(), b.end(), pairs_.begin());
  pair_count_ = static_cast<std::size_t>(std::unique(pairs_.begin(), end) - pairs_.begin());
  stats_ = colliders_[0].stats();
  if (helper_) {
    const CollisionStats& h = colliders_[1].stats();
    stats_.sphere_tests += h.sphere_tests;
    stats_.leaf_pairs += h.leaf_pairs;
    stats_.triangle_tests += h.triangle_tests;
  }
  return share_ok_[0] && share_ok_[1];
}

}  // namespace resecto
