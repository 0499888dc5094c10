// JobThread: a thread that runs one fixed job each time its owner launches it, and lets the owner wait
// for that run to finish. The core launches the collision refit and search at one tick and waits for
// it at a fixed later tick, so how long the job takes never changes what the core computes, only how
// long the wait is. The handoff is two atomic counters and futexes (futex.h): no mutex, no allocation
// after construction.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <thread>
#include <utility>

#include "rtcore/base/flush_denormals.h"
#include "rtcore/concurrency/futex.h"

namespace resecto {

class JobThread {
 public:
  /// Starts the thread, idle; `job` runs on it once per launch().
  explicit JobThread(std::function<void()> job) : job_(std::move(job)), thread_([this] { run(); }) {}
  ~JobThread() {
    wait();
    stopping_.store(true, std::memory_order_relaxed);
    launched_.fetch_add(1, std::memory_order_release);
    futex_wake_one(launched_);
    thread_.join();
  }
  JobThread(const JobThread&) = delete;
  JobThread& operator=(const JobThread&) = delete;

  /// Owner only, while idle (after wait()): runs the job once more. What the owner wrote before this
  /// call is visible to the job.
  void launch() {
    launched_.fetch_add(1, std::memory_order_release);
    futex_wake_one(launched_);
  }

  /// Owner only: returns once the last launched run has finished (at once if it has); what the job
  /// wrote is then visible to the owner. Returns whether it had to wait.
  bool wait() {
    const std::uint32_t target = launched_.load(std::memory_order_relaxed);
    std::uint32_t done = finished_.load(std::memory_order_acquire);
    if (done == target) return false;
    while (done != target) {
      futex_sleep_while_equal(finished_, done);
      done = finished_.load(std::memory_order_acquire);
    }
    return true;
  }

  /// The OS thread, e.g. to give it a real-time priority.
  std::thread::native_handle_type native_handle() { return thread_.native_handle(); }

  /// Owner only: whether the last launched run has finished.
  bool idle() const { return finished_.load(std::memory_order_acquire) == launched_.load(std::memory_order_relaxed); }

 private:
  void run() {
    flush_denormals_on_this_thread();  // the core's arithmetic, on whichever thread it runs
    std::uint32_t seen = 0;
    for (;;) {
      while (launched_.load(std::memory_order_acquire) == seen) futex_sleep_while_equal(launched_, seen);
      seen = launched_.load(std::memory_order_acquire);
      if (stopping_.load(std::memory_order_relaxed)) return;
      job_();
      finished_.store(seen, std::memory_order_release);
      futex_wake_one(finished_);
    }
  }


  std::function<void()> job_;
  std::atomic<std::uint32_t> launched_{0};
  std::atomic<std::uint32_t> finished_{0};
  std::atomic<bool> stopping_{false};
  std::thread thread_;  // last: starts once the rest exists
};

}  // namespace resecto
