// BoxColumns::within against the plain per-box test: random boxes (some flat, some points), points
// inside, outside and on faces, every count from 0 to 9 (the four-wide loop's tail) and a long list.
#include "rtcore/geometry/box_columns.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

namespace resecto {
namespace {

struct Box {
  Vec3 low, high;
};

std::vector<std::uint32_t> within_by_hand(const std::vector<Box>& boxes, const Vec3& p, double reach2) {
  std::vector<std::uint32_t> found;
  for (std::uint32_t k = 0; k < boxes.size(); ++k) {
    const Vec3 gap = glm::max(glm::max(boxes[k].low - p, p - boxes[k].high), Vec3(0.0));
    if (glm::dot(gap, gap) <= reach2) found.push_back(k);
  }
  return found;
}

TEST(BoxColumns, FindsTheBoxesWithinReachInOrderAsTheirPlainTestDoes) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0), extent(0.0, 0.4);
  std::vector<Box> all;
  for (int k = 0; k < 1000; ++k) {
    const Vec3 low(coordinate(random), coordinate(random), coordinate(random));
    Vec3 size(extent(random), extent(random), extent(random));
    if (k % 7 == 0) size.y = 0.0;  // flat
    if (k % 11 == 0) size = Vec3(0.0);  // a point
    all.push_back({low, low + size});
  }
  std::vector<Vec3> points;
  for (int k = 0; k < 300; ++k) points.emplace_back(1.3 * coordinate(random), 1.3 * coordinate(random), 1.3 * coordinate(random));
  points.push_back(all[3].low);                               // a corner
  points.push_back(0.5 * (all[5].low + all[5].high));        // inside
  points.emplace_back(all[8].high.x, all[8].low.y, all[8].low.z);  // on an edge
  for (const std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{4}, std::size_t{5},
                                  std::size_t{6}, std::size_t{7}, std::size_t{8}, std::size_t{9}, all.size()}) {
    const std::vector<Box> boxes(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(count));
    BoxColumns columns;
    columns.reserve(count);
    for (const Box& b : boxes) columns.push(b.low, b.high);
    ASSERT_EQ(columns.size(), count);
    std::vector<std::uint32_t> indices(count + 1);
    for (const Vec3& p : points) {
      for (const double reach : {0.0, 0.05, 0.3}) {
        const std::size_t found = columns.within(p, reach * reach, indices.data());
        const std::vector<std::uint32_t> expected = within_by_hand(boxes, p, reach * reach);
        ASSERT_EQ(std::vector<std::uint32_t>(indices.begin(), indices.begin() + static_cast<std::ptrdiff_t>(found)), expected)
            << count << " boxes, reach " << reach << ", at " << p.x << ", " << p.y << ", " << p.z;
      }
    }
  }
}

TEST(BoxColumns, ClearedHoldsNoBox) {
  BoxColumns columns;
  columns.push(Vec3(0.0), Vec3(1.0));
  columns.clear();
  EXPECT_EQ(columns.size(), 0u);
  std::uint32_t index = 99;
  EXPECT_EQ(columns.within(Vec3(0.5), 1.0, &index), 0u);
}

}  // namespace
}  // namespace resecto
