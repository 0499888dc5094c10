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
  waits_per_chunk_.reserve(chunks);
  waiters_end_.reserve(chunks);
  summed_.reserve(node_capacity / kGroup + 1);
  if (chunks > waits_capacity_) {
    waits_ = std::make_unique<std::atomic<std::uint32_t>[]>(chunks);
    waits_capacity_ = chunks;
  }
  deferred_.reserve(node_capacity, nodes_per_chunk);
  node_chunk_.reserve(node_capacity);
  group_deferred_.reserve(node_capacity / kGroup + 1);
}

void SpringSumSchedule::rebuild(const SteppedNodes& stepped, const SpringArrays& springs, const SpringIncidence& incidence,
                                std::size_t node_count, std::size_t nodes_per_chunk) {
  assert(incidence.first_first.size() == node_count + 1 && incidence.second_first.size() == node_count + 1);
  const std::uint32_t chunks = stepped.chunk_count();
  reserve(node_count, nodes_per_chunk);  // free within the room already reserved
  spring_first_.clear();
  summed_.clear();
  summed_first_.clear();
  waits_per_chunk_.clear();
  waiters_end_.clear();
  // Chunk c's node range runs from its first span (chunk 0's from node 0) to the next chunk's, so
  // the ranges tile every node and their springs (sorted by node i) tile every spring.
  auto range_begin = [&](std::uint32_t c) -> std::uint32_t { return c == 0 ? 0 : stepped.chunk(c).front().begin; };
  node_chunk_.resize(node_count);
  for (std::uint32_t c = 0, n = 0; c < chunks; ++c) {
    const std::uint32_t end = c + 1 < chunks ? range_begin(c + 1) : static_cast<std::uint32_t>(node_count);
    for (; n < end; ++n) node_chunk_[n] = c;
  }
  group_deferred_.assign((node_count + kGroup - 1) / kGroup, 0);
  summed_first_.push_back(0);
  for (std::uint32_t c = 0; c < chunks; ++c) {
    std::uint32_t first = c;  // the first chunk whose springs this one's sums read
    for (const NodeSpan span : stepped.chunk(c)) {
      for (std::uint32_t group = span.begin; group < span.end; group += kGroup) {
        const std::uint32_t group_end = std::min<std::uint32_t>(group + kGroup, span.end);
        std::uint32_t group_first = c;
        bool late = false;
        for (std::uint32_t n = group; n < group_end; ++n) {
          // A node's springs as node i are in its own chunk; as node j, in the chunk of their node i.
          for (std::uint32_t e = incidence.second_first[n]; e < incidence.second_first[n + 1]; ++e) {
            const std::uint32_t k = node_chunk_[springs.i[incidence.second_springs[e]]];
            late = late || k > c;
            group_first = std::min(group_first, k);
          }
        }
        if (late) {
          group_deferred_[group / kGroup] = 1;
          continue;
        }
        first = std::min(first, group_first);
        if (summed_.size() > summed_first_.back() && summed_.back().end == group) {
          summed_.back().end = group_end;
        } else {
          summed_.push_back({group, group_end});
        }
      }
    }
    summed_first_.push_back(static_cast<std::uint32_t>(summed_.size()));
    waits_per_chunk_.push_back(c + 1 - first);
    spring_first_.push_back(incidence.first_first[range_begin(c)]);
  }
  spring_first_.push_back(incidence.first_first[node_count]);
  // A chunk also waits for whatever a later chunk waits for (a running minimum from the back), so
  // the chunks waiting for chunk k are one run [k, waiters_end_[k]): a wait more changes no sum.
  for (std::uint32_t c = chunks; c-- > 1;) {
    const std::uint32_t later_first = first_needed(c);
    if (later_first < first_needed(c - 1)) waits_per_chunk_[c - 1] = c - later_first;
  }
  for (std::uint32_t k = 0, c = 0; k < chunks; ++k) {
    while (c < chunks && first_needed(c) <= k) ++c;
    waiters_end_.push_back(c);
  }
  deferred_.rebuild(node_count, nodes_per_chunk, [&](std::uint32_t n) { return group_deferred_[n / kGroup] != 0; });
}

}  // namespace resecto
