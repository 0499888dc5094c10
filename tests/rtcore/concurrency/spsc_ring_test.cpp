// SpscRing: FIFO order, capacity limits, and a two-thread stress run (millions of items, no loss,
// no reordering) that the thread sanitizer build checks for data races.
#include "rtcore/concurrency/spsc_ring.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <thread>
#include <vector>

namespace resecto {
namespace {

TEST(SpscRing, RoundsCapacityUpToPowerOfTwo) {
  EXPECT_EQ(SpscRing<int>(0).capacity(), 2u);
  EXPECT_EQ(SpscRing<int>(5).capacity(), 8u);
  EXPECT_EQ(SpscRing<int>(1024).capacity(), 1024u);
}

TEST(SpscRing, RefusesWhenFullAndKeepsFifoOrder) {
  SpscRing<int> ring(4);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(99));
  EXPECT_EQ(ring.size_approx(), 4u);
  int out = -1;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, i);
  }
  EXPECT_FALSE(ring.try_pop(out));
  EXPECT_EQ(out, 3);  // untouched by the failed pop
  EXPECT_TRUE(ring.empty_approx());
}

TEST(SpscRing, WrapsAroundManyLaps) {
  SpscRing<std::uint64_t> ring(8);
  std::uint64_t next_in = 0, next_out = 0, out = 0;
  for (int lap = 0; lap < 1000; ++lap) {
    // Uneven bursts so head and tail cross the wrap point at every offset.
    const int burst = 1 + lap % 8;
    for (int i = 0; i < burst; ++i) ASSERT_TRUE(ring.try_push(next_in++));
    for (int i = 0; i < burst; ++i) {
      ASSERT_TRUE(ring.try_pop(out));
      ASSERT_EQ(out, next_out++);
    }
  }
}

TEST(SpscRing, MovesNonTrivialItems) {
  SpscRing<std::string> ring(2);
  std::string long_text(200, 'x');
  EXPECT_TRUE(ring.try_push(std::move(long_text)));
  std::string out;
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, std::string(200, 'x'));
}

TEST(SpscRing, PopLatestKeepsNewest) {
  SpscRing<int> ring(8);
  int out = -1;
  EXPECT_EQ(ring.pop_latest(out), 0u);
  EXPECT_EQ(out, -1);
  for (int i = 10; i < 15; ++i) ASSERT_TRUE(ring.try_push(i));
  EXPECT_EQ(ring.pop_latest(out), 5u);
  EXPECT_EQ(out, 14);
}

// An item whose fields are checked against each other, so a torn read (half old, half new) shows.
struct StressItem {
  std::uint64_t sequence = 0;
  std::uint64_t check = 0;
  double payload[6] = {};
};

TEST(SpscRing, TwoThreadStressLosesAndReordersNothing) {
  constexpr std::uint64_t kItems = 2'000'000;
  SpscRing<StressItem> ring(256);  // small, so both the full and the empty paths run often
  std::uint64_t producer_full_retries = 0;

  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      StressItem item;
      item.sequence = i;
      item.check = i * 0x9E3779B97F4A7C15ull;
      for (int k = 0; k < 6; ++k) item.payload[k] = static_cast<double>(i + static_cast<std::uint64_t>(k));
      while (!ring.try_push(item)) {
        ++producer_full_retries;
        std::this_thread::yield();
      }
    }
  });

  std::uint64_t expected = 0;
  std::uint64_t bad = 0;
  StressItem out;
  while (expected < kItems) {
    if (!ring.try_pop(out)) {
      std::this_thread::yield();
      continue;
    }
    if (out.sequence != expected || out.check != expected * 0x9E3779B97F4A7C15ull) ++bad;
    for (int k = 0; k < 6; ++k) {
      if (out.payload[k] != static_cast<double>(expected + static_cast<std::uint64_t>(k))) ++bad;
    }
    ++expected;
  }
  producer.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(expected, kItems);
  EXPECT_FALSE(ring.try_pop(out));
  RecordProperty("producer_full_retries", std::to_string(producer_full_retries));
}

}  // namespace
}  // namespace resecto
