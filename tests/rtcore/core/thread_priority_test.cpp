// Real-time scheduling: raising to SCHED_FIFO where the OS permits it, and always coming back.
#include "rtcore/core/thread_priority.h"

#include <gtest/gtest.h>
#include <sched.h>

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
