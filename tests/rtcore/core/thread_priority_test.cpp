// Real-time scheduling: raising to SCHED_FIFO where the OS permits it, and always coming back.
#include "rtcore/core/thread_priority.h"

#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <thread>

namespace resecto {
namespace {

int policy_of(pthread_t thread, int* priority = nullptr) {
  int policy = -1;
  sched_param param{};
  EXPECT_EQ(pthread_getschedparam(thread, &policy, &param), 0);
  if (priority) *priority = param.sched_priority;
  return policy;
}

TEST(ThreadPriority, ScopedRaiseEitherTakesEffectOrChangesNothing) {
  std::thread worker([] {
    const pthread_t self = pthread_self();
    const int before = policy_of(self);
    {
      ScopedFifoPriority raised(kCoreFifoPriority);
      int priority = 0;
      const int during = policy_of(self, &priority);
      if (raised.raised()) {
        EXPECT_EQ(during, SCHED_FIFO);
        EXPECT_EQ(priority, kCoreFifoPriority);
      } else {
        EXPECT_EQ(during, before) << "a refused raise must leave the thread as it was";
      }
    }
    EXPECT_EQ(policy_of(self), before) << "the scope restores normal scheduling";
  });
  worker.join();
}

TEST(ThreadPriority, TheCoreKeepsAProcessorOfItsOwnAndTheHelperTheOthers) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  ASSERT_EQ(sched_getaffinity(0, sizeof allowed, &allowed), 0);
  // Two threads that live until the checks are done (an ended thread has no affinity to read).
  std::atomic<bool> done{false};
  const auto wait_for_done = [&done] {
    while (!done.load(std::memory_order_acquire)) std::this_thread::yield();
  };
  std::thread core_thread(wait_for_done), helper_thread(wait_for_done);
  const pthread_t core = core_thread.native_handle(), helper = helper_thread.native_handle();
  const pthread_t others[] = {helper};
  const int placed = keep_core_apart(core, others);
  cpu_set_t core_set, helper_set;
  const bool read = pthread_getaffinity_np(core, sizeof core_set, &core_set) == 0 && pthread_getaffinity_np(helper, sizeof helper_set, &helper_set) == 0;
  done.store(true, std::memory_order_release);
  core_thread.join();
  helper_thread.join();
  if (CPU_COUNT(&allowed) < 2) {
    EXPECT_EQ(placed, -1) << "one processor: nothing to keep apart";
    return;
  }
  ASSERT_GE(placed, 0) << "affinity refused here";
  ASSERT_TRUE(read);
  int last = -1;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) last = cpu;
  }
  EXPECT_EQ(placed, last);
  EXPECT_EQ(CPU_COUNT(&core_set), 1);
  EXPECT_TRUE(CPU_ISSET(last, &core_set));
  EXPECT_FALSE(CPU_ISSET(last, &helper_set)) << "a helper level with the core must not share its processor";
  EXPECT_EQ(CPU_COUNT(&helper_set), CPU_COUNT(&allowed) - 1);
}

TEST(ThreadPriority, OutOfRangePriorityIsRefused) {
  std::thread worker([] {
    const pthread_t self = pthread_self();
    const int before = policy_of(self);
    EXPECT_FALSE(raise_to_fifo(self, 0));
    EXPECT_FALSE(raise_to_fifo(self, 100));
    EXPECT_EQ(policy_of(self), before);
  });
  worker.join();
}

}  // namespace
}  // namespace resecto
