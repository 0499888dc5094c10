// The spring sums' schedule (spring_sum_schedule.h) against its definition, on spring networks with
// the locality of a node order and with refinement's late springs: the chunks' springs tile every
// spring once, every stepped group is summed once (in a chunk or deferred), a chunk's summed nodes
// read only springs of the chunks it waits for, and in any order the chunks may complete, each
// chunk is summed once, only after every chunk it waits for.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "rtcore/tissue/spring_forces.h"
#include "rtcore/tissue/spring_sum_schedule.h"
#include "rtcore/tissue/stepped_nodes.h"

namespace resecto {
namespace {

constexpr std::size_t kPerChunk = 64;

/// Springs i < j within `reach` of each other in node order (as the locality order leaves them),
/// then `late` springs as refinement appends them: node i the last node, node j anywhere.
SpringForces local_network(std::uint32_t nodes, std::uint32_t reach, std::uint32_t late, std::mt19937& random) {
  SpringNetwork network;
  std::uniform_int_distribution<std::uint32_t> offset(1, reach);
  for (std::uint32_t i = 0; i + 1 < nodes; ++i) {
    std::vector<std::uint32_t> js;
    for (int k = 0; k < 4; ++k) js.push_back(std::min(nodes - 1, i + offset(random)));
    std::sort(js.begin(), js.end());
    js.erase(std::unique(js.begin(), js.end()), js.end());
    for (std::uint32_t j : js) {
      network.spring_nodes.push_back(i);
      network.spring_nodes.push_back(j);
      network.rest_length_m.push_back(0.001);
      network.volume_share_m3.push_back(1e-9);
    }
  }
  network.node_volume_m3.assign(nodes, 1e-9);
  SpringForces springs(network);
  springs.reserve(network.spring_count() + late, nodes);
  const std::size_t first_new = springs.spring_count();
  std::uniform_int_distribution<std::uint32_t> any(0, nodes - 2);
  std::vector<std::uint32_t> late_js;
  for (std::uint32_t k = 0; k < late; ++k) late_js.push_back(any(random));
  std::sort(late_js.begin(), late_js.end());
  late_js.erase(std::unique(late_js.begin(), late_js.end()), late_js.end());
  for (std::uint32_t j : late_js) springs.append(nodes - 1, j, 0.001);
  springs.add_appended_to_incidence(first_new);
  return springs;
}

SteppedNodes some_stepped(std::uint32_t nodes, double fraction, std::mt19937& random) {
  std::bernoulli_distribution stepped_node(fraction);
  std::vector<bool> needed(nodes);
  for (std::uint32_t n = 0; n < nodes; ++n) needed[n] = stepped_node(random);
  SteppedNodes stepped;
  stepped.reserve(nodes, kPerChunk);
  stepped.rebuild(nodes, kPerChunk, [&](std::uint32_t n) { return needed[n]; });
  return stepped;
}

void expect_schedule_holds(const SteppedNodes& stepped, const SpringForces& springs, std::uint32_t nodes, std::mt19937& random) {
  SpringSumSchedule schedule;
  schedule.reserve(nodes, kPerChunk);
  schedule.rebuild(stepped, springs.arrays(), springs.incidence(), nodes, kPerChunk);
  const SpringIncidence& incidence = springs.incidence();
  const std::uint32_t chunks = schedule.chunk_count();
  ASSERT_EQ(chunks, stepped.chunk_count());
  ASSERT_GT(chunks, 4u);

  // The chunks' springs tile [0, spring count), each chunk's being those of the nodes it ranges over.
  std::vector<std::uint32_t> chunk_of_spring(springs.spring_count());
  EXPECT_EQ(schedule.spring_begin(0), 0u);
  EXPECT_EQ(schedule.spring_begin(chunks), springs.spring_count());
  for (std::uint32_t c = 0; c < chunks; ++c) {
    ASSERT_LE(schedule.spring_begin(c), schedule.spring_begin(c + 1));
    for (std::uint32_t s = schedule.spring_begin(c); s < schedule.spring_begin(c + 1); ++s) chunk_of_spring[s] = c;
    for (const NodeSpan span : stepped.chunk(c)) {
      for (std::uint32_t n = span.begin; n < span.end; ++n) {
        for (std::uint32_t s = incidence.first_first[n]; s < incidence.first_first[n + 1]; ++s) EXPECT_EQ(chunk_of_spring[s], c) << s;
      }
    }
  }

  // Every stepped node summed once: in the chunk holding it or deferred; a summed node's springs
  // all lie in the chunks its chunk waits for.
  std::vector<int> summed(nodes, 0), in_chunk(nodes, -1);
  for (std::uint32_t c = 0; c < chunks; ++c) {
    for (const NodeSpan span : stepped.chunk(c)) {
      for (std::uint32_t n = span.begin; n < span.end; ++n) in_chunk[n] = static_cast<int>(c);
    }
  }
  std::size_t deferred_nodes = 0;
  for (std::uint32_t c = 0; c < chunks; ++c) {
    for (const NodeSpan span : schedule.summed_spans(c)) {
      ASSERT_EQ(span.begin % SteppedNodes::kGroup, 0u);
      for (std::uint32_t n = span.begin; n < span.end; ++n) {
        ++summed[n];
        ASSERT_EQ(in_chunk[n], static_cast<int>(c)) << "node " << n;
        for (std::uint32_t e = incidence.second_first[n]; e < incidence.second_first[n + 1]; ++e) {
          const std::uint32_t k = chunk_of_spring[incidence.second_springs[e]];
          EXPECT_GE(k, schedule.first_needed(c)) << "node " << n;
          EXPECT_LE(k, c) << "node " << n;
        }
      }
    }
  }
  for (const NodeSpan span : schedule.deferred().spans()) {
    for (std::uint32_t n = span.begin; n < span.end; ++n) {
      ++summed[n];
      ++deferred_nodes;
    }
  }
  for (std::uint32_t n = 0; n < nodes; ++n) EXPECT_EQ(summed[n], in_chunk[n] >= 0 ? 1 : 0) << "node " << n;
  EXPECT_GT(deferred_nodes, 0u) << "the late springs must defer some groups";
  EXPECT_LT(deferred_nodes, nodes / 4) << "only the late springs' groups";

  // Chunks completing in any order, as two threads claiming from both ends (or one alone) may.
  for (int order = 0; order < 20; ++order) {
    std::vector<std::uint32_t> completion(chunks);
    std::iota(completion.begin(), completion.end(), 0u);
    if (order == 1) std::reverse(completion.begin(), completion.end());
    if (order > 1) std::shuffle(completion.begin(), completion.end(), random);
    std::vector<bool> computed(chunks, false);
    std::vector<int> sums(chunks, 0);
    schedule.arm();
    for (std::uint32_t k : completion) {
      computed[k] = true;
      schedule.finish(k, [&](std::uint32_t c) {
        ++sums[c];
        for (std::uint32_t needed = schedule.first_needed(c); needed <= c; ++needed) EXPECT_TRUE(computed[needed]) << c << " before " << needed;
      });
    }
    for (std::uint32_t c = 0; c < chunks; ++c) EXPECT_EQ(sums[c], 1) << "order " << order << " chunk " << c;
  }
}

TEST(SpringSumSchedule, EveryNodeSummedOnceAfterTheChunksItsSpringsAreIn) {
  std::mt19937 random(7);
  for (const std::uint32_t reach : {3u, 40u, 300u}) {
    const std::uint32_t nodes = 2003;
    SpringForces springs = local_network(nodes, reach, 25, random);
    for (const double fraction : {1.0, 0.6, 0.15}) {
      SCOPED_TRACE(testing::Message() << "reach " << reach << ", stepped fraction " << fraction);
      expect_schedule_holds(some_stepped(nodes, fraction, random), springs, nodes, random);
    }
  }
}

TEST(SpringSumSchedule, ARebuildWithinTheReservedRoomAllocatesNothing) {
  std::mt19937 random(11);
  const std::uint32_t nodes = 4000;
  SpringForces springs = local_network(nodes, 100, 10, random);
  const SteppedNodes every = some_stepped(nodes, 1.0, random), few = some_stepped(nodes, 0.2, random);
  SpringSumSchedule schedule;
  schedule.reserve(nodes, kPerChunk);
  schedule.rebuild(every, springs.arrays(), springs.incidence(), nodes, kPerChunk);
  const std::uint32_t first_chunk_spring = schedule.spring_begin(1);
  const auto* spans = schedule.summed_spans(0).data();
  schedule.rebuild(few, springs.arrays(), springs.incidence(), nodes, kPerChunk);
  schedule.rebuild(every, springs.arrays(), springs.incidence(), nodes, kPerChunk);
  EXPECT_EQ(schedule.summed_spans(0).data(), spans) << "the spans stayed where they were reserved";
  EXPECT_EQ(schedule.spring_begin(1), first_chunk_spring);
}

}  // namespace
}  // namespace resecto
