// The spans a physics step's node loops walk (stepped_nodes.h) against the plain definition: every
// node that must be stepped lies in a span, every group of four a span covers holds one, spans start
// on a group and ascend, and the chunks share the listed nodes out in full chunks and one last part.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "rtcore/tissue/stepped_nodes.h"

namespace resecto {
namespace {

void expect_spans_list_exactly_the_needed_groups(const std::vector<bool>& needed, std::size_t per_chunk) {
  SteppedNodes stepped;
  stepped.reserve(needed.size(), per_chunk);
  stepped.rebuild(needed.size(), per_chunk, [&](std::uint32_t n) { return needed[n]; });
  std::vector<bool> covered(needed.size(), false);
  std::uint32_t previous_end = 0;
  std::size_t listed = 0;
  for (std::uint32_t c = 0; c < stepped.chunk_count(); ++c) {
    std::size_t in_chunk = 0;
    for (const NodeSpan span : stepped.chunk(c)) {
      ASSERT_EQ(span.begin % SteppedNodes::kGroup, 0u);
      ASSERT_LT(span.begin, span.end);
      ASSERT_LE(span.end, needed.size());
      ASSERT_GE(span.begin, previous_end) << "spans ascend and do not overlap";
      previous_end = span.end;
      for (std::uint32_t n = span.begin; n < span.end; ++n) covered[n] = true;
      in_chunk += span.end - span.begin;
    }
    listed += in_chunk;
    if (c + 1 < stepped.chunk_count()) {
      EXPECT_EQ(in_chunk, per_chunk) << "chunk " << c;
    } else {
      EXPECT_LE(in_chunk, per_chunk);
      EXPECT_GT(in_chunk, 0u);
    }
  }
  EXPECT_EQ(listed, stepped.listed_nodes());
  for (std::size_t group = 0; group < needed.size(); group += SteppedNodes::kGroup) {
    bool any = false;
    for (std::size_t n = group; n < std::min(needed.size(), group + SteppedNodes::kGroup); ++n) any = any || needed[n];
    for (std::size_t n = group; n < std::min(needed.size(), group + SteppedNodes::kGroup); ++n) {
      EXPECT_EQ(covered[n], any) << "node " << n << " of " << needed.size();
    }
  }
}

TEST(SteppedNodes, ListExactlyTheGroupsHoldingANodeToStep) {
  std::mt19937_64 random(7);
  for (const std::size_t n : {0, 1, 3, 4, 5, 63, 64, 65, 1001, 4099}) {
    for (const double density : {0.0, 0.02, 0.3, 0.9, 1.0}) {
      std::bernoulli_distribution pick(density);
      std::vector<bool> needed(n);
      for (std::size_t i = 0; i < n; ++i) needed[i] = pick(random);
      for (const std::size_t per_chunk : {4, 16, 512}) expect_spans_list_exactly_the_needed_groups(needed, per_chunk);
    }
  }
}

TEST(SteppedNodes, ARebuildWithinTheReservedRoomAllocatesNothing) {
  SteppedNodes stepped;
  const std::size_t capacity = 10000;
  stepped.reserve(capacity, 16);
  // The most spans: every other group.
  stepped.rebuild(capacity, 16, [](std::uint32_t n) { return (n / SteppedNodes::kGroup) % 2 == 0; });
  const NodeSpan* spans = stepped.spans().data();
  stepped.rebuild(capacity, 16, [](std::uint32_t) { return true; });
  stepped.rebuild(capacity, 16, [](std::uint32_t n) { return (n / SteppedNodes::kGroup) % 2 == 1; });
  EXPECT_EQ(stepped.spans().data(), spans) << "the spans' storage moved: the reserve was short";
}

}  // namespace
}  // namespace resecto
