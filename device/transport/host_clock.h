// HostClock: the link's only source of host time. The live link uses the steady clock; tests and
// batch runs use a virtual clock that sleeping advances, so every timeout, backoff and latency figure
// is reproducible and a simulated minute of unplugging takes no real time.
#pragma once

#include <atomic>
#include <cstdint>

namespace resecto {

/// Monotonic host time in nanoseconds and a way to wait for it.
class HostClock {
 public:
  virtual ~HostClock() = default;
  /// Nanoseconds since an arbitrary, fixed origin; never decreases.
  virtual std::int64_t now_ns() const = 0;
  /// Returns once now_ns() >= deadline_ns (immediately if already past).
  virtual void sleep_until_ns(std::int64_t deadline_ns) = 0;
};

/// std::chrono::steady_clock and real sleeps.
class SteadyHostClock final : public HostClock {
 public:
  std::int64_t now_ns() const override;
  void sleep_until_ns(std::int64_t deadline_ns) override;
};

/// Time that moves only when someone sleeps or advances it. Thread-safe: the link thread sleeps on it
/// while a test thread reads it.
class VirtualHostClock final : public HostClock {
 public:
  explicit VirtualHostClock(std::int64_t start_ns = 0) : now_ns_(start_ns) {}
  std::int64_t now_ns() const override { return now_ns_.load(std::memory_order_acquire); }
  void sleep_until_ns(std::int64_t deadline_ns) override;
  /// Moves time forward by `delta_ns` (>= 0).
  void advance_ns(std::int64_t delta_ns);

 private:
  std::atomic<std::int64_t> now_ns_;
};

inline constexpr std::int64_t kNanosecondsPerMicrosecond = 1000;
inline constexpr std::int64_t kNanosecondsPerMillisecond = 1000 * 1000;
inline constexpr std::int64_t kNanosecondsPerSecond = 1000 * 1000 * 1000;

}  // namespace resecto
