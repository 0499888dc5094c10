// SpscRing: a bounded lock-free queue between exactly one producer thread and one consumer thread
// (device link -> core, core -> recorder, console -> core). Capacity is fixed at construction, so
// pushing and popping never allocate, never lock and never block: a full ring refuses the item and
// the producer counts it.
#pragma once

#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace resecto {

/// Bytes between two atomics that two threads write, so they never share a cache line.
inline constexpr std::size_t kCacheLineBytes = 64;

/// Bounded single-producer/single-consumer FIFO. `try_push` from one thread, `try_pop` from one
/// other thread; `size_approx`, `capacity` and `empty_approx` from either.
template <class T>
class SpscRing {
  static_assert(std::is_default_constructible_v<T>, "slots are constructed up front");
  static_assert(std::is_nothrow_move_assignable_v<T>, "a move must not throw halfway through a push");

 public:
  /// A ring holding at least `min_capacity` items (rounded up to a power of two, at least 2).
  explicit SpscRing(std::size_t min_capacity)
      : capacity_(round_up_to_power_of_two(min_capacity < 2 ? 2 : min_capacity)),
        mask_(capacity_ - 1),
        slots_(std::make_unique<T[]>(capacity_)) {}

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  /// Producer only. Moves `item` in and returns true, or returns false (item untouched) when full.
  bool try_push(T&& item) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_cache_ >= capacity_) {
      // Only reload the consumer's index when the cached one says full: one shared read per lap.
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail - head_cache_ >= capacity_) return false;
    }
    slots_[tail & mask_] = std::move(item);
    tail_.store(tail + 1, std::memory_order_release);  // publishes the slot's contents
    return true;
  }

  /// Producer only. Copies `item` in; false when full.
  bool try_push(const T& item) noexcept(std::is_nothrow_copy_constructible_v<T>) {
    T copy = item;
    return try_push(std::move(copy));
  }

  /// Consumer only. Moves the oldest item into `out` and returns true, or false when empty.
  bool try_pop(T& out) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_cache_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head == tail_cache_) return false;
    }
    out = std::move(slots_[head & mask_]);
    head_.store(head + 1, std::memory_order_release);  // hands the slot back to the producer
    return true;
  }

  /// Consumer only. Pops everything available, keeping only the newest in `out`; returns how many
  /// were popped (0: `out` untouched). For a consumer that only wants the latest state.
  std::size_t pop_latest(T& out) noexcept {
    std::size_t popped = 0;
    while (try_pop(out)) ++popped;
    return popped;
  }

  /// Items in the ring at some instant during the call (exact only when both sides are idle).
  std::size_t size_approx() const noexcept {
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    const std::uint64_t tail = tail_.load(std::memory_order_acquire);
    return tail >= head ? static_cast<std::size_t>(tail - head) : 0;
  }

  bool empty_approx() const noexcept { return size_approx() == 0; }

  std::size_t capacity() const noexcept { return capacity_; }

 private:
  static std::size_t round_up_to_power_of_two(std::size_t n) {
    std::size_t p = 1;
    while (p < n) p <<= 1;
    return p;
  }

  const std::size_t capacity_;
  const std::size_t mask_;
  std::unique_ptr<T[]> slots_;

  // 64-bit monotonic indices never wrap in practice (centuries at a GHz), so full/empty need no
  // extra flag. Each side's index and its cache of the other's index sit on the side's own line.
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> head_{0};  ///< next slot to pop; consumer writes
  std::uint64_t tail_cache_ = 0;                                 ///< consumer's view of tail_
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> tail_{0};  ///< next slot to push; producer writes
  std::uint64_t head_cache_ = 0;                                 ///< producer's view of head_
};

}  // namespace resecto
