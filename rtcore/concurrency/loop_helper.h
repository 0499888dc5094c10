// LoopHelper: a second thread that shares the physics step's data-parallel loops with the core.
// A loop is cut into a fixed number of chunks; the core claims them one at a time from the front and
// the helper from the back until none is left, and each chunk writes only its own slice of the output. Which thread ran a
// chunk therefore never changes a bit of the result, and a helper that is late, descheduled or
// absent only means the core runs more chunks itself: it never waits for the helper to arrive, only
// for a chunk the helper has already claimed.
//
// The helper sleeps on a futex between ticks and is called in for the loops of one step (it then
// spins, so a chunk starts within a fraction of a microsecond). Called in for loops that do not come
// (the owner stopped or paused between call_in() and its step), it goes home by itself after
// kIdleOnCall: spinning at a real-time priority it would hold a processor from every lower thread,
// the owner's own collision job among them, and two such processes on two processors then wait on
// each other for ever. No mutex, no allocation after construction: the loop's body is passed as a
// function pointer and a context pointer.
#pragma once

#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "rtcore/base/flush_denormals.h"
#include "rtcore/concurrency/futex.h"
#include "rtcore/concurrency/spin_pause.h"

namespace resecto {

/// Work the owner does beside a shared loop, while the helper starts on the loop's chunks: a
/// function and its context (no allocation, unlike a std::function). Empty: nothing.
struct SideTask {
  void (*run)(void*) = nullptr;
  void* context = nullptr;
  void operator()() const {
    if (run != nullptr) run(context);
  }
};
/// A SideTask that calls `task()`; `task` must outlive it.
template <class Task>
SideTask side_task(Task& task) {
  return {[](void* context) { (*static_cast<Task*>(context))(); }, &task};
}

class LoopHelper {
 public:
  /// The most chunks one loop may have.
  static constexpr std::uint32_t kMaxChunks = 0xffff;
  /// How long the helper stays on call with no new loop before it goes home by itself: far longer
  /// than any gap between one step's loops (its serial parts) at a size that runs in real time.
  static constexpr std::chrono::milliseconds kIdleOnCall{5};

  LoopHelper() : thread_([this] { run(); }) {}
  ~LoopHelper() {
    stopping_.store(true, std::memory_order_relaxed);
    // Not 1: a helper going home by itself swaps an on-call 1 for 0 (run()), and would take this
    // wake-up with it and sleep through the join. Its swap fails on kStopping.
    on_call_.store(kStopping, std::memory_order_release);
    futex_wake_one(on_call_);
    thread_.join();
  }
  LoopHelper(const LoopHelper&) = delete;
  LoopHelper& operator=(const LoopHelper&) = delete;

  /// Owner: wakes the helper to take part in the loops that follow, until send_home().
  void call_in() {
    when_ready_ = {};
    if (on_call_.exchange(1, std::memory_order_release) == 0) futex_wake_one(on_call_);
  }
  /// Owner: the helper goes back to sleep once it sees this (no loop is running: for_each_chunk has
  /// returned).
  void send_home() {
    when_ready_ = {};
    on_call_.store(0, std::memory_order_relaxed);
  }
  /// Owner: until call_in() or send_home(), the loops check `ready(context)` before and between their
  /// chunks, and once it holds call the helper in, which joins the running loop's unclaimed chunks.
  /// The core runs a step alone while its collision job has the second processor, and takes the
  /// helper back as soon as the job ends rather than at the next step.
  void call_in_when(bool (*ready)(const void*), const void* context) { when_ready_ = {ready, context}; }
  /// Whether the helper is on call (called in, and not yet sent or gone home).
  bool on_call() const { return on_call_.load(std::memory_order_relaxed) != 0; }

  /// Owner: body(chunk) for every chunk in [0, chunks), run by this thread and the helper (if it is on
  /// call); returns once all have run, with their writes visible. A loop of more than kMaxChunks
  /// chunks runs on this thread alone.
  /// `alongside` runs on this thread once the loop is offered, before it claims chunks: the helper
  /// starts on them meanwhile. It must touch nothing the chunks write.
  template <class Body>
  void for_each_chunk(std::uint32_t chunks, Body& body, SideTask alongside = {}) {
    if (chunks == 0 || chunks > kMaxChunks) {
      alongside();
      for (std::uint32_t chunk = 0; chunk < chunks; ++chunk) body(chunk);
      return;
    }
    offered_ += chunks;
    body_.store(&call_body<Body>, std::memory_order_relaxed);
    context_.store(&body, std::memory_order_relaxed);
    finished_.store(0, std::memory_order_relaxed);
    ++generation_;
    const std::uint64_t loop = (static_cast<std::uint64_t>(generation_) << 32) | (static_cast<std::uint64_t>(chunks) << 16);
    work_.store(loop, std::memory_order_release);
    alongside();
    std::uint32_t ran = 0;
    call_in_if_ready();
    for (std::uint32_t chunk = 0; claim(generation_, true, chunk);) {
      body(chunk);
      ++ran;
      call_in_if_ready();
    }
    // Only chunks the helper claimed are outstanding; it is running them now.
    std::uint32_t done = finished_.fetch_add(ran, std::memory_order_acq_rel) + ran;
    for (std::uint32_t spins = 0; done != chunks; done = finished_.load(std::memory_order_acquire)) {
      // Should the helper share this CPU (an affinity mask, a migration), let it run.
      if (++spins > (1u << 16)) sched_yield();
      spin_pause();
    }
  }

  /// The helper's OS thread, e.g. to give it a real-time priority.
  std::thread::native_handle_type native_handle() { return thread_.native_handle(); }
  /// How many chunks the helper has run since it started (for reports and tests).
  std::uint64_t chunks_helped() const { return helped_.load(std::memory_order_relaxed); }
  /// Owner: how many chunks its loops have had in all.
  std::uint64_t chunks_offered() const { return offered_; }
  /// How many times the helper went home by itself, called in for loops that did not come.
  std::uint64_t times_gone_home() const { return gone_home_.load(std::memory_order_relaxed); }

 private:
  // work_: generation (32 bits) | end of the unclaimed chunks (16) | start of the unclaimed chunks (16).
  static std::uint32_t generation_of(std::uint64_t w) { return static_cast<std::uint32_t>(w >> 32); }
  static std::uint32_t back_of(std::uint64_t w) { return static_cast<std::uint32_t>(w >> 16) & 0xffff; }
  static std::uint32_t front_of(std::uint64_t w) { return static_cast<std::uint32_t>(w) & 0xffff; }

  // Claims the first unclaimed chunk (the owner) or the last (the helper) of loop `generation`; false
  // once none is left or another loop began. Taking them from opposite ends gives each thread about
  // the same half of the data every step, which then stays in its own core's cache. The bounds
  // travel in the same word as the claim, so a claim never pairs one loop with another's size.
  bool claim(std::uint32_t generation, bool from_front, std::uint32_t& chunk) {
    std::uint64_t w = work_.load(std::memory_order_acquire);
    for (;;) {
      if (generation_of(w) != generation || front_of(w) >= back_of(w)) return false;
      const std::uint64_t claimed = from_front ? w + 1 : w - (std::uint64_t{1} << 16);
      if (work_.compare_exchange_weak(w, claimed, std::memory_order_acq_rel, std::memory_order_acquire)) {
        chunk = from_front ? front_of(w) : back_of(w) - 1;
        return true;
      }
    }
  }

  struct ReadyCheck {
    bool (*ready)(const void*) = nullptr;
    const void* context = nullptr;
  };
  void call_in_if_ready() {
    if (when_ready_.ready != nullptr && when_ready_.ready(when_ready_.context)) call_in();
  }

  template <class Body>
  static void call_body(void* context, std::uint32_t chunk) {
    (*static_cast<Body*>(context))(chunk);
  }

  void run() {
    flush_denormals_on_this_thread();  // the core's arithmetic, on whichever thread it runs
    std::uint32_t seen = 0;
    std::uint32_t idle_spins = 0;
    std::chrono::steady_clock::time_point idle_since{};
    for (;;) {
      if (on_call_.load(std::memory_order_acquire) == 0) {
        while (on_call_.load(std::memory_order_acquire) == 0) futex_sleep_while_equal(on_call_, 0);
        idle_spins = 0;
      }
      if (stopping_.load(std::memory_order_relaxed)) return;
      const std::uint64_t w = work_.load(std::memory_order_acquire);
      const std::uint32_t generation = generation_of(w);
      if (generation == seen) {
        // The clock only now and then: a pause lasts tens of cycles on one processor, over a hundred
        // on another. Going home is always safe: the owner never waits for the helper to arrive.
        if (idle_spins++ % 1024 == 0) {
          const auto now = std::chrono::steady_clock::now();
          if (idle_spins == 1) idle_since = now;
          if (now - idle_since > kIdleOnCall) {
            std::uint32_t called = 1;
            if (on_call_.compare_exchange_strong(called, 0, std::memory_order_relaxed)) gone_home_.fetch_add(1, std::memory_order_relaxed);
          }
        }
        spin_pause();
        continue;
      }
      // Sent home as this loop came: the owner runs it alone. Not marked seen, so a helper called in
      // again while it runs (call_in_when) still joins it.
      if (on_call_.load(std::memory_order_acquire) == 0) continue;
      idle_spins = 0;
      seen = generation;
      std::uint32_t ran = 0;
      for (std::uint32_t chunk = 0; claim(generation, false, chunk);) {
        // A claimed chunk holds its loop open, so the body read here is that loop's.
        body_.load(std::memory_order_relaxed)(context_.load(std::memory_order_relaxed), chunk);
        ++ran;
      }
      if (ran > 0) {
        helped_.fetch_add(ran, std::memory_order_relaxed);
        finished_.fetch_add(ran, std::memory_order_release);
      }
    }
  }


  std::uint32_t generation_ = 0;  // owner only
  std::uint64_t offered_ = 0;     // owner only
  ReadyCheck when_ready_;         // owner only: call_in_when()
  alignas(64) std::atomic<std::uint64_t> work_{0};
  std::atomic<void (*)(void*, std::uint32_t)> body_{nullptr};
  std::atomic<void*> context_{nullptr};
  alignas(64) std::atomic<std::uint32_t> finished_{0};
  static constexpr std::uint32_t kStopping = 2;  // on_call_ from the destructor on
  alignas(64) std::atomic<std::uint32_t> on_call_{0};
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint64_t> helped_{0};
  std::atomic<std::uint64_t> gone_home_{0};
  std::thread thread_;  // last: starts once the rest exists
};

/// body(chunk) for every chunk in [0, chunks): shared with `helper` where there is one, else in order on
/// this thread. Either way each chunk runs once, so the result is the same. `alongside` runs on this
/// thread too, before it takes any chunk (see LoopHelper::for_each_chunk).
template <class Body>
void for_each_chunk(LoopHelper* helper, std::uint32_t chunks, Body& body, SideTask alongside = {}) {
  if (helper != nullptr) {
    helper->for_each_chunk(chunks, body, alongside);
  } else {
    alongside();
    for (std::uint32_t chunk = 0; chunk < chunks; ++chunk) body(chunk);
  }
}

/// How many chunks of `per_chunk` items cover `count` items.
constexpr std::uint32_t chunks_covering(std::size_t count, std::size_t per_chunk) {
  return static_cast<std::uint32_t>((count + per_chunk - 1) / per_chunk);
}

}  // namespace resecto
