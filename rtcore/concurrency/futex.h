// Linux futexes called directly on a std::atomic<uint32_t>: the sleep and wake the core's helper
// threads hand work over with (JobThread, LoopHelper). No mutex, no allocation. (Not
// std::atomic::wait: GCC 12's libstdc++ skips the wake when its waiter count looks zero, and a test
// caught it losing a wake-up.)
#pragma once

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>

namespace resecto {

static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t) && std::atomic<std::uint32_t>::is_always_lock_free);

/// Sleeps while `word` holds `value`. The kernel compares and sleeps in one step, so a wake between
/// the caller's check and the sleep is never lost; spurious returns are fine, callers re-check.
inline void futex_sleep_while_equal(std::atomic<std::uint32_t>& word, std::uint32_t value) {
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAIT_PRIVATE, value, nullptr, nullptr, 0);
}

/// Wakes one thread sleeping on `word`.
inline void futex_wake_one(std::atomic<std::uint32_t>& word) {
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAKE_PRIVATE, 1, nullptr, nullptr, 0);
}

}  // namespace resecto
