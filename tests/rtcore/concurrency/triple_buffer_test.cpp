// The triple buffer under two threads: the reader sees snapshots in publish order, never a torn one,
// and always the newest once the writer stops. Run it in the tsan preset too.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include "rtcore/concurrency/triple_buffer.h"

namespace resecto {
namespace {

/// A snapshot big enough that a torn copy would show: every word holds the same sequence number.
struct Snapshot {
  std::array<std::uint64_t, 64> words{};
};

TEST(TripleBuffer, SingleThreadLatestWins) {
  TripleBuffer<int> buffer(0);
  EXPECT_FALSE(buffer.update());
  EXPECT_EQ(buffer.read_slot(), 0);
  buffer.write_slot() = 1;
  buffer.publish();
  buffer.write_slot() = 2;
  buffer.publish();
  EXPECT_TRUE(buffer.update());
  EXPECT_EQ(buffer.read_slot(), 2);  // 1 was overtaken
  EXPECT_FALSE(buffer.update());
  EXPECT_EQ(buffer.read_slot(), 2);
  buffer.write_slot() = 3;
  buffer.publish();
  EXPECT_TRUE(buffer.update());
  EXPECT_EQ(buffer.read_slot(), 3);
}

TEST(TripleBuffer, TwoThreadsNeverTearAndNeverGoBack) {
  constexpr std::uint64_t kPublishes = 2'000'000;
  TripleBuffer<Snapshot> buffer;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t n = 1; n <= kPublishes; ++n) {
      Snapshot& slot = buffer.write_slot();
      for (auto& w : slot.words) w = n;
      buffer.publish();
    }
    done.store(true, std::memory_order_release);
  });
  std::uint64_t last_seen = 0, updates = 0, torn = 0, backwards = 0;
  auto take = [&] {
    if (!buffer.update()) return;
    ++updates;
    const Snapshot& s = buffer.read_slot();
    for (auto w : s.words) torn += w != s.words[0] ? 1 : 0;
    backwards += s.words[0] <= last_seen ? 1 : 0;
    last_seen = s.words[0];
  };
  while (!done.load(std::memory_order_acquire)) take();
  writer.join();
  take();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_EQ(last_seen, kPublishes);  // the newest snapshot always arrives
  EXPECT_GT(updates, 0u);
}

}  // namespace
}  // namespace resecto
