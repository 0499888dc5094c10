#include "rtcore/tissue/spring_sum_schedule.h"

#include <algorithm>
#include <cassert>

#include "rtcore/concurrency/loop_helper.h"

namespace resecto {

namespace {
constexpr std::size_t kGroup = SteppedNodes::kGroup;
}

void SpringSumSchedule::reserve(std::size_t node_capacity, std::size_t nodes_per_chunk) {
  const std::size_t chunks = chunks_covering(node_capacity, nodes_per_chunk) + 1;
  spring_first_.reserve(chunks + 1);
  summed_first_.reserve(chunks + 1);
  first_wait_.reserve(chunks);
  waiters_end_.reserve(chunks);
  summed_.reserve(node_capacity / kGroup + 1);
  if (chunks > waits_.size()) waits_ = std::vector<std::atomic<std::uint32_t>>(chunks);
  deferred_.reserve(node_capacity, nodes_per_chunk);
  node_chunk_.reserve(node_capacity);
  group_flags_.reserve(node_capacity / kGroup + 1);
}

void SpringSumSchedule::rebuild(const SteppedNodes& stepped, const SpringArrays& springs, const SpringIncidence& incidence,
                                std::size_t node_count, std::size_t nodes_per_chunk) {
  assert(incidence.first_first.size() == node_count + 1);
  const std::uint32_t chunks = stepped.chunk_count();
  reserve(node_count, nodes_per_chunk);  // free within the room already reserved
  // Chunk c's node range runs from its first span (chunk 0's from node 0) to the next chunk's, so
  // the ranges tile every node and their springs (sorted by node i) tile every spring.
  auto range_begin = [&](std::uint32_t c) -> std::uint32_t { return c == 0 ? 0 : stepped.chunk(c).front().begin; };
  node_chunk_.resize(node_count);
  spring_first_.clear();
  for (std::uint32_t c = 0, n = 0; c < chunks; ++c) {
    const std::uint32_t end = c + 1 < chunks ? range_begin(c + 1) : static_cast<std::uint32_t>(node_count);
    for (; n < end; ++n) node_chunk_[n] = c;
    spring_first_.push_back(incidence.first_first[range_begin(c)]);
  }
  spring_first_.push_back(incidence.first_first[node_count]);

  // One sequential pass over the springs: spring s of chunk c (its node i there) reaches its node j
  // in chunk c or later (the mesh's springs, i < j), whose sums then wait for chunk c, or in an
  // earlier chunk (refinement's springs, i > j), whose group of four is then summed after the pass.
  // Orphans' springs count too: a wait more changes no sum.
  first_wait_.resize(chunks);
  for (std::uint32_t c = 0; c < chunks; ++c) first_wait_[c] = c;
  group_flags_.assign((node_count + kGroup - 1) / kGroup, 0);
  for (std::uint32_t c = 0; c < chunks; ++c) {
    for (std::uint32_t s = spring_first_[c]; s < spring_first_[c + 1]; ++s) {
      const std::uint32_t j = springs.j[s];
      const std::uint32_t chunk_j = node_chunk_[j];
      if (chunk_j < c) {
        group_flags_[j / kGroup] |= kLate;
      } else {
        first_wait_[chunk_j] = std::min(first_wait_[chunk_j], c);
      }
    }
  }
  // A chunk also waits for whatever a later chunk waits for (a running minimum from the back), so
  // the chunks waiting for chunk k are one run [k, waiters_end_[k]).
  for (std::uint32_t c = chunks; c-- > 1;) first_wait_[c - 1] = std::min(first_wait_[c - 1], first_wait_[c]);
  waiters_end_.clear();
  for (std::uint32_t k = 0, c = 0; k < chunks; ++k) {
    while (c < chunks && first_wait_[c] <= k) ++c;
    waiters_end_.push_back(c);
  }

  // Each chunk's stepped groups, but the late ones, summed in the pass.
  summed_.clear();
  summed_first_.clear();
  summed_first_.push_back(0);
  for (std::uint32_t c = 0; c < chunks; ++c) {
    for (const NodeSpan span : stepped.chunk(c)) {
      for (std::uint32_t group = span.begin; group < span.end; group += kGroup) {
        std::uint8_t& flags = group_flags_[group / kGroup];
        flags |= kStepped;
        if ((flags & kLate) != 0) continue;
        const std::uint32_t group_end = std::min<std::uint32_t>(group + kGroup, span.end);
        if (summed_.size() > summed_first_.back() && summed_.back().end == group) {
          summed_.back().end = group_end;
        } else {
          summed_.push_back({group, group_end});
        }
      }
    }
    summed_first_.push_back(static_cast<std::uint32_t>(summed_.size()));
  }
  deferred_.rebuild(node_count, nodes_per_chunk, [&](std::uint32_t n) { return group_flags_[n / kGroup] == (kStepped | kLate); });
}

}  // namespace resecto
