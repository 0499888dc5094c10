// JobThread: every launch runs the job exactly once, the owner sees all the job wrote once wait()
// returns, and the job sees all the owner wrote before launch() (run under the thread sanitizer).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "rtcore/concurrency/job_thread.h"

namespace resecto {
namespace {

TEST(JobThread, EachLaunchRunsOnceAndItsWritesAreSeenAfterTheWait) {
  // Plain (non-atomic) data handed back and forth: any missing happens-before edge is a race the
  // thread sanitizer reports, and any lost or doubled run shows in the values.
  std::vector<std::uint64_t> input(64, 0), output(64, 0);
  std::uint64_t runs = 0;
  JobThread worker([&] {
    ++runs;
    for (std::size_t i = 0; i < input.size(); ++i) output[i] = input[i] * 3 + 1;
  });
  constexpr std::uint64_t kLaunches = 200'000;
  for (std::uint64_t n = 1; n <= kLaunches; ++n) {
    for (std::size_t i = 0; i < input.size(); ++i) input[i] = n + i;
    worker.launch();
    if (n % 7 == 0) std::this_thread::yield();  // sometimes the job is done before the wait
    worker.wait();
    ASSERT_EQ(runs, n);
    for (std::size_t i = 0; i < output.size(); ++i) ASSERT_EQ(output[i], (n + i) * 3 + 1) << "launch " << n << ", item " << i;
  }
}

TEST(JobThread, WaitWhenIdleReturnsAtOnceAndDestructionJoins) {
  std::atomic<int> runs{0};
  {
    JobThread worker([&] { runs.fetch_add(1); });
    EXPECT_FALSE(worker.wait());
    EXPECT_TRUE(worker.idle());
    worker.launch();
    // Destroyed with the run possibly in flight: it finishes, then the thread stops.
  }
  EXPECT_EQ(runs.load(), 1);
}

}  // namespace
}  // namespace resecto
