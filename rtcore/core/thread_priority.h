// Real-time scheduling for the threads of a real-time run. On a machine shared with other work (a
// compiler, a browser) a normal thread can be preempted for milliseconds, several ticks; SCHED_FIFO
// threads run before every normal one. Only where the OS permits it (root or CAP_SYS_NICE); otherwise
// the run goes on at normal priority and says so.
#pragma once

#include <pthread.h>

#include <span>
#include <string>

namespace resecto {

/// A real-time run's priorities (1..99): above every normal thread, below the kernel's threaded
/// interrupt handlers (FIFO 50 on PREEMPT_RT kernels), which carry the device's USB reports; the
/// core first, the collision thread (which has a whole collision period) next.
inline constexpr int kCoreFifoPriority = 45;
inline constexpr int kCollisionFifoPriority = 40;
/// The recorder thread (recordings/): below both, above every normal thread, so a loaded machine
/// cannot starve the recording of a real-time run (it needs ~5% of a core).
inline constexpr int kRecorderFifoPriority = 30;

/// Puts `thread` under SCHED_FIFO at `priority` (1..99); false (nothing changed) if not permitted.
bool raise_to_fifo(pthread_t thread, int priority);
/// Back to the default time-sharing policy.
void restore_normal_scheduling(pthread_t thread);

/// Keeps a real-time core's thread on a processor of its own among those this process may use: the
/// last one, with `others` (its physics helper) on the rest. Processor 0 takes the machine's
/// housekeeping: on the development VM a system agent's timer wakes there every ~1.05 s and its work
/// holds the processor ~2 ms (the kernel does not preempt it), and a core sleeping between ticks on
/// that processor started a tick that late about once a second (session 44's console runs; its
/// headless runs, whose core had landed on processor 1, did not). A helper level with the core must
/// not share its processor either: SCHED_FIFO at one priority does not preempt. Returns the core's
/// processor, or -1 (nothing changed) with fewer than two processors or where the OS refuses.
int keep_core_apart(pthread_t core, std::span<const pthread_t> others);

/// Raises the calling thread for its lifetime and restores it after. A plain object rather than an
/// optional one for runs that may not want it: GCC's flow analysis under the sanitizers took an
/// empty std::optional of it for one read uninitialized (-Wmaybe-uninitialized).
class ScopedFifoPriority {
 public:
  /// Raises the calling thread only when `wanted` (a real-time run; a batch one keeps its priority).
  ScopedFifoPriority(int priority, bool wanted) : thread_(pthread_self()), raised_(wanted && raise_to_fifo(thread_, priority)) {}
  explicit ScopedFifoPriority(int priority) : ScopedFifoPriority(priority, true) {}
  ~ScopedFifoPriority() { restore(); }
  ScopedFifoPriority(const ScopedFifoPriority&) = delete;
  ScopedFifoPriority& operator=(const ScopedFifoPriority&) = delete;
  bool raised() const { return raised_; }
  /// Back to normal scheduling now; the destructor then has nothing left to do.
  void restore() {
    if (raised_) restore_normal_scheduling(thread_);
    raised_ = false;
  }

 private:
  pthread_t thread_;
  bool raised_;
};

}  // namespace resecto
