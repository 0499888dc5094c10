// RealtimeProbe: counts heap allocations and mutex locks made by any thread while a probe is open,
// so a test can prove a steady-state step allocates nothing and takes no lock. Linking test_support
// replaces the global operator new and interposes pthread_mutex_lock in that test binary.
#pragma once

namespace resecto::testing {

class RealtimeProbe {
 public:
  /// Whose allocations and locks count: every thread's, or only the opening thread's (the core's,
  /// while the collision thread works alongside and may allocate).
  enum class Threads { kAll, kThisOne };
  explicit RealtimeProbe(Threads threads = Threads::kAll);  ///< starts counting
  ~RealtimeProbe();  ///< stops counting
  RealtimeProbe(const RealtimeProbe&) = delete;
  RealtimeProbe& operator=(const RealtimeProbe&) = delete;

  long allocations() const;
  long locks() const;

 private:
  bool this_thread_only_;
};

}  // namespace resecto::testing
