// TripleBuffer: the core publishes its latest snapshot, the console (or any reader) takes the newest
// one whenever it wants. Three slots and one atomic index: the writer never waits for the reader and
// the reader never sees a slot the writer is filling, so a snapshot is never torn. Latest wins: a
// snapshot the reader did not take before the next publish is dropped, by design.
#pragma once

#include <atomic>
#include <cstdint>
#include <utility>

namespace resecto {

/// Lock-free latest-value exchange between exactly one writer thread and one reader thread.
template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  /// Every slot starts as a copy of `initial` (so preallocated capacities exist in all three).
  explicit TripleBuffer(const T& initial) : slots_{initial, initial, initial} {}

  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  /// Writer only: the slot to fill next. It is not visible to the reader until publish().
  T& write_slot() { return slots_[write_index_]; }

  /// Writer only: makes the write slot the newest snapshot and takes the old middle slot to write.
  void publish() {
    const std::uint8_t previous =
        middle_.exchange(static_cast<std::uint8_t>(write_index_ | kFreshBit), std::memory_order_acq_rel);
    write_index_ = previous & kIndexMask;
  }

  /// Reader only: swaps in the newest snapshot if there is one; returns whether it was new.
  bool update() {
    if ((middle_.load(std::memory_order_relaxed) & kFreshBit) == 0) return false;
    const std::uint8_t previous = middle_.exchange(read_index_, std::memory_order_acq_rel);
    read_index_ = previous & kIndexMask;
    return true;
  }

  /// Reader only: the snapshot taken by the last update() (the initial value before any).
  const T& read_slot() const { return slots_[read_index_]; }

 private:
  static constexpr std::uint8_t kFreshBit = 0x4;
  static constexpr std::uint8_t kIndexMask = 0x3;

  T slots_[3]{};
  std::uint8_t write_index_ = 0;               // writer's own
  std::uint8_t read_index_ = 1;                // reader's own
  std::atomic<std::uint8_t> middle_{2};        // the exchange slot, plus "fresh" when written since read
};

}  // namespace resecto
