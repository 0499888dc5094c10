// When each node's spring sum may run inside the per-spring pass rather than in a pass of its own.
// Summed in a second pass over the nodes, every spring's force (a 32-byte row) was written by the
// first pass and read back twice from memory: at 138,240 triangles the 720,000 rows (23 MB) have
// left the caches by then, and the sums were a third of the physics step or more. In locality order
// (node_order.h) a node's springs are its own (as node i) or those of nodes a little before it, so
// once the chunks of the spring pass that hold a chunk's springs are done, that chunk can be summed
// while their forces are still in cache.
//
// The spring pass runs in the node loop's chunks (SteppedNodes): chunk c computes the springs whose
// node i lies in its node range, the ranges tiling every node, orphans included, so every spring is
// computed once as before. Chunk c's sums wait for the chunks [first_needed(c), c]; each chunk
// counts down its waits, and whichever thread computes the last of them sums it, in any claim order.
// A node sums exactly the springs it did, in the same order, so no bit of a force changes. A group
// of four holding a node with a spring from a later chunk (refinement's springs: their node i is a
// new node, numbered after every original one) is summed after the pass instead ("deferred").
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/tissue/spring_kernel.h"
#include "rtcore/tissue/stepped_nodes.h"

namespace resecto {

class SpringSumSchedule {
 public:
  /// Room for `node_capacity` nodes in chunks of `nodes_per_chunk`, so a rebuild within them
  /// allocates nothing.
  void reserve(std::size_t node_capacity, std::size_t nodes_per_chunk);

  /// Plans the pass over `stepped`'s chunks for springs sorted by node i (`springs`, `incidence`)
  /// among `node_count` nodes.
  void rebuild(const SteppedNodes& stepped, const SpringArrays& springs, const SpringIncidence& incidence, std::size_t node_count,
               std::size_t nodes_per_chunk);

  std::uint32_t chunk_count() const { return static_cast<std::uint32_t>(first_wait_.size()); }
  /// The springs chunk c computes: [spring_begin(c), spring_begin(c + 1)).
  std::uint32_t spring_begin(std::uint32_t c) const { return spring_first_[c]; }
  /// Each chunk's first spring, in chunk order.
  std::span<const std::uint32_t> spring_begins() const { return std::span<const std::uint32_t>(spring_first_).first(chunk_count()); }
  /// The spans of chunk c summed inside the pass (its stepped groups that are not deferred).
  std::span<const NodeSpan> summed_spans(std::uint32_t c) const {
    return std::span<const NodeSpan>(summed_).subspan(summed_first_[c], summed_first_[c + 1] - summed_first_[c]);
  }
  /// The groups summed after the pass, in chunks of their own.
  const SteppedNodes& deferred() const { return deferred_; }
  /// The first of the chunks chunk c's sums wait for (they wait for all from it to c).
  std::uint32_t first_needed(std::uint32_t c) const { return first_wait_[c]; }

  /// Before each pass: every chunk waits for all of its chunks again.
  void arm() {
    for (std::uint32_t c = 0; c < chunk_count(); ++c) waits_[c].store(c + 1 - first_wait_[c], std::memory_order_relaxed);
  }
  /// After chunk k's springs are computed (on any thread): calls sum(c) for each chunk c that k was
  /// the last wait of. The count-down's acquire-release makes every needed chunk's writes visible
  /// to the thread that sums.
  template <class Sum>
  void finish(std::uint32_t k, Sum&& sum) {
    for (std::uint32_t c = k; c < waiters_end_[k]; ++c) {
      if (waits_[c].fetch_sub(1, std::memory_order_acq_rel) == 1) sum(c);
    }
  }

 private:
  std::vector<std::uint32_t> spring_first_;     // per chunk + 1
  std::vector<NodeSpan> summed_;                // every chunk's summed spans, in chunk order
  std::vector<std::uint32_t> summed_first_;     // per chunk + 1, into summed_
  std::vector<std::uint32_t> first_wait_;   // chunk c waits for [first_wait_[c], c]
  std::vector<std::uint32_t> waiters_end_;  // chunk k is waited for by [k, waiters_end_[k])
  std::vector<std::atomic<std::uint32_t>> waits_;  // per chunk (room for every chunk), counting down in a pass
  SteppedNodes deferred_;
  // Rebuild scratch: each node's chunk, each group's flags.
  static constexpr std::uint8_t kStepped = 1, kLate = 2;
  std::vector<std::uint32_t> node_chunk_;
  std::vector<std::uint8_t> group_flags_;
};

}  // namespace resecto
