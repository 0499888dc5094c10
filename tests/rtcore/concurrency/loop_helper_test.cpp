// LoopHelper: every chunk of every loop runs exactly once, whoever runs it; what the chunks wrote is
// seen by the owner when the loop returns, and what the owner wrote before it by the chunks (plain
// data, so the thread sanitizer reports a missing edge). A helper that is sleeping, being called in,
// or sent home between loops never loses or doubles a chunk.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "rtcore/concurrency/loop_helper.h"

namespace resecto {
namespace {

TEST(LoopHelper, EveryChunkRunsOnceAndItsWritesAreSeen) {
  LoopHelper helper;
  std::vector<std::uint64_t> input(4096, 0), output(4096, 0), runs(4096, 0);
  constexpr int kLoops = 20'000;
  for (int loop = 1; loop <= kLoops; ++loop) {
    // Loops of every size from one chunk up, the helper on call for some and asleep for others.
    const auto chunks = static_cast<std::uint32_t>(1 + (loop * 37) % 64);
    if (loop % 5 == 0) helper.send_home();
    if (loop % 5 == 2) helper.call_in();
    for (std::uint32_t c = 0; c < chunks; ++c) input[c] = static_cast<std::uint64_t>(loop) * 1000 + c;
    auto body = [&](std::uint32_t chunk) {
      output[chunk] = input[chunk] * 3 + 1;
      ++runs[chunk];
    };
    helper.for_each_chunk(chunks, body);
    for (std::uint32_t c = 0; c < chunks; ++c) {
      ASSERT_EQ(output[c], input[c] * 3 + 1) << "loop " << loop << ", chunk " << c;
      ASSERT_EQ(runs[c], 1u) << "loop " << loop << ", chunk " << c;
      runs[c] = 0;
    }
  }
  helper.send_home();
  EXPECT_LE(helper.chunks_helped(), helper.chunks_offered());
}

TEST(LoopHelper, TheHelperTakesChunksFromTheOtherEnd) {
  // With the helper on call and a loop long enough for it to arrive, it runs some chunks, and they
  // are the loop's last ones: the owner's share is a prefix, the helper's the rest.
  LoopHelper helper;
  const std::thread::id owner = std::this_thread::get_id();
  std::vector<int> by_owner(256, -1);
  std::vector<std::uint64_t> sink(256, 0);
  bool helped = false;
  for (int attempt = 0; attempt < 1000 && !helped; ++attempt) {
    // Called in for every loop, as the core does each step: an owner descheduled for over kIdleOnCall
    // between loops (ctest -j2 on a loaded machine) had let the helper go home for every later attempt.
    helper.call_in();
    auto body = [&](std::uint32_t chunk) {
      by_owner[chunk] = std::this_thread::get_id() == owner ? 1 : 0;
      std::uint64_t work = chunk;
      for (int spin = 0; spin < 20'000; ++spin) work = work * 6364136223846793005u + 1442695040888963407u;
      sink[chunk] = work;  // a few microseconds a chunk, so the helper has time to arrive
    };
    helper.for_each_chunk(256, body);
    std::size_t first_helped = 256;
    for (std::size_t c = 0; c < by_owner.size(); ++c) {
      if (by_owner[c] == 0 && first_helped == 256) first_helped = c;
      if (c >= first_helped) {
        ASSERT_EQ(by_owner[c], 0) << "chunk " << c << " after the helper's first " << first_helped;
      }
    }
    helped = first_helped < 256;
  }
  helper.send_home();
  EXPECT_TRUE(helped) << "the helper never ran a chunk";
  EXPECT_GT(helper.chunks_helped(), 0u);
}

TEST(LoopHelper, CalledInWhenReadyItJoinsTheRunningLoop) {
  // The core runs a step alone while its collision job has the second processor, and takes the helper
  // back once the job ends: the owner checks between chunks and calls it in, and it joins the loop
  // already running. Here another thread plays the job: it ends while the owner runs chunk 0; chunk
  // 1 then waits (up to 10 s, for a loaded machine) until some chunk has run on a thread not the owner's.
  LoopHelper helper;
  helper.send_home();
  const std::thread::id owner = std::this_thread::get_id();
  std::atomic<bool> started{false}, job_ended{false}, joined{false};
  std::thread job([&] {
    while (!started.load()) std::this_thread::yield();
    job_ended.store(true);
  });
  helper.call_in_when([](const void* ended) { return static_cast<const std::atomic<bool>*>(ended)->load(); }, &job_ended);
  std::atomic<std::uint32_t> runs{0};
  auto body = [&](std::uint32_t chunk) {
    runs.fetch_add(1);
    if (std::this_thread::get_id() != owner) joined.store(true);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    if (chunk == 0) {
      EXPECT_FALSE(helper.on_call()) << "called in before the job ended";
      started.store(true);
      while (!job_ended.load() && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
    } else if (chunk == 1) {
      while (!joined.load() && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
    }
  };
  helper.for_each_chunk(64, body);
  job.join();
  EXPECT_TRUE(helper.on_call()) << "the job's end called the helper in";
  helper.send_home();
  EXPECT_TRUE(joined.load()) << "the helper, called in during the loop, ran none of its chunks";
  EXPECT_EQ(runs.load(), 64u) << "every chunk runs once";
  EXPECT_GT(helper.chunks_helped(), 0u);
}

TEST(LoopHelper, NotReadyTheHelperStaysHome) {
  // call_in_when() whose condition never holds: the owner runs every chunk, the helper none.
  LoopHelper helper;
  helper.send_home();
  helper.call_in_when([](const void*) { return false; }, nullptr);
  const std::thread::id owner = std::this_thread::get_id();
  std::vector<int> by_owner(64, -1);
  auto body = [&](std::uint32_t chunk) { by_owner[chunk] = std::this_thread::get_id() == owner ? 1 : 0; };
  helper.for_each_chunk(64, body);
  EXPECT_FALSE(helper.on_call());
  EXPECT_EQ(std::count(by_owner.begin(), by_owner.end(), 1), 64);
  EXPECT_EQ(helper.chunks_helped(), 0u);
}

TEST(LoopHelper, WithoutAHelperTheChunksRunInOrderOnTheCaller) {
  std::vector<std::uint32_t> order;
  auto body = [&](std::uint32_t chunk) { order.push_back(chunk); };
  for_each_chunk(nullptr, 5, body);
  EXPECT_EQ(order, (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(chunks_covering(0, 512), 0u);
  EXPECT_EQ(chunks_covering(512, 512), 1u);
  EXPECT_EQ(chunks_covering(513, 512), 2u);
}

TEST(LoopHelper, TheSideTaskRunsOnceOnTheOwnerBesideTheHelpersChunks) {
  // The physics step finds the contact forces this way while the helper starts on the springs: the
  // side task runs on the owner, once, before the owner takes a chunk, whether the helper is on call,
  // asleep or absent, and for an empty loop too; what it wrote is the owner's, and the chunks' writes
  // are seen when the loop returns (plain data: the thread sanitizer checks both).
  LoopHelper helper;
  const std::thread::id owner = std::this_thread::get_id();
  std::vector<std::uint64_t> output(64, 0);
  std::uint64_t side_result = 0;
  for (int loop = 0; loop < 5'000; ++loop) {
    if (loop % 3 == 0) helper.call_in();
    if (loop % 3 == 2) helper.send_home();
    const auto chunks = static_cast<std::uint32_t>(loop % 65);
    int side_runs = 0;
    std::uint32_t owner_chunks_before_side = 0;
    auto body = [&](std::uint32_t chunk) {
      if (std::this_thread::get_id() == owner && side_runs == 0) ++owner_chunks_before_side;
      output[chunk] = static_cast<std::uint64_t>(loop) * 100 + chunk;
    };
    auto side = [&] {
      ASSERT_EQ(std::this_thread::get_id(), owner);
      ++side_runs;
      side_result = static_cast<std::uint64_t>(loop);
    };
    for_each_chunk(loop % 7 == 0 ? nullptr : &helper, chunks, body, side_task(side));
    ASSERT_EQ(side_runs, 1) << "loop " << loop;
    ASSERT_EQ(owner_chunks_before_side, 0u) << "loop " << loop;
    ASSERT_EQ(side_result, static_cast<std::uint64_t>(loop));
    for (std::uint32_t c = 0; c < chunks; ++c) ASSERT_EQ(output[c], static_cast<std::uint64_t>(loop) * 100 + c) << "loop " << loop;
  }
  helper.send_home();
  int runs = 0;
  auto count = [&] { ++runs; };
  auto nothing = [](std::uint32_t) {};
  helper.for_each_chunk(LoopHelper::kMaxChunks + 1, nothing, side_task(count));  // past what it can count: on the caller
  EXPECT_EQ(runs, 1);
  SideTask{}();  // an empty task does nothing
}

TEST(LoopHelper, ALoopOfMoreChunksThanItCanCountRunsOnTheCaller) {
  LoopHelper helper;
  helper.call_in();
  const std::uint32_t chunks = LoopHelper::kMaxChunks + 3;
  std::vector<std::uint8_t> runs(chunks, 0);
  auto body = [&](std::uint32_t chunk) { ++runs[chunk]; };
  helper.for_each_chunk(chunks, body);
  helper.send_home();
  EXPECT_EQ(std::count(runs.begin(), runs.end(), 1), static_cast<std::ptrdiff_t>(chunks));
  EXPECT_EQ(helper.chunks_helped(), 0u);
}

TEST(LoopHelper, CalledInForLoopsThatDoNotComeItGoesHomeByItself) {
  // A core stopped or paused between call_in() and its step must not leave the helper spinning (at
  // a real-time priority that holds a processor from every lower thread for as long as it lasts).
  LoopHelper helper;
  // Read before the call: a test thread descheduled between the two would otherwise start its clock
  // late and see the helper leave "early" (seen: 3.2 ms of the 5 on a loaded machine).
  const auto called = std::chrono::steady_clock::now();
  helper.call_in();
  while (helper.on_call() && std::chrono::steady_clock::now() - called < std::chrono::seconds(10)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_FALSE(helper.on_call());
  EXPECT_GE(std::chrono::steady_clock::now() - called, LoopHelper::kIdleOnCall);
  EXPECT_EQ(helper.times_gone_home(), 1u);
  // Called in again, it takes part as before, and every chunk still runs exactly once.
  std::vector<std::atomic<int>> runs(64);
  auto body = [&](std::uint32_t chunk) {
    runs[chunk].fetch_add(1, std::memory_order_relaxed);
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  };
  // Until the helper has taken part once: a loaded machine may not run it for a while.
  int loops = 0;
  const auto again = std::chrono::steady_clock::now();
  for (; helper.chunks_helped() == 0 && std::chrono::steady_clock::now() - again < std::chrono::seconds(20); ++loops) {
    helper.call_in();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    helper.for_each_chunk(64, body);
    helper.send_home();
  }
  EXPECT_GT(helper.chunks_helped(), 0u);
  for (std::size_t chunk = 0; chunk < runs.size(); ++chunk) EXPECT_EQ(runs[chunk].load(), loops) << "chunk " << chunk;
}

TEST(LoopHelper, DestructionJoinsWhetherAsleepOrOnCall) {
  { LoopHelper asleep; }
  {
    LoopHelper on_call;
    on_call.call_in();
  }
  SUCCEED();
}

}  // namespace
}  // namespace resecto
