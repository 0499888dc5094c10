// Fault injection through the whole link on the emulator: with drops, duplicates and corruption over
// 10,000 reports, the statistics count exactly what was injected, nothing corrupt reaches the
// consumer, and the samples that do are the right ones, in order. Virtual time: runs in well under a second.
#include "device/transport/fault_injection.h"

#include <gtest/gtest.h>

#include <array>
#include <map>

#include "device/transport/emulator_transport.h"
#include "tests/device/link_test_support.h"

namespace resecto {
namespace {

using testing::poll_and_drain;
using testing::smooth_motion;

struct FaultRun {
  std::vector<DeviceSample> delivered;
  InjectedFaults injected;
  LinkCounters counters;
};

// Runs the emulator through the fault wrapper into a link until `reports` have left the board, then
// stops injecting and reads one more clean report so that a trailing fault shows as a gap.
FaultRun run_with_faults(const FaultConfig& config, std::uint64_t reports) {
  VirtualHostClock clock;
  firmware::Emulator emulator;
  emulator.set_motion(&smooth_motion);
  EmulatorTransport board(emulator, clock);
  FaultInjectingTransport faulty(board, clock, config);
  DeviceLink link(faulty, clock);
  FaultRun run;
  poll_and_drain(link, run.delivered, [&] { return faulty.injected().passed >= reports; });
  run.injected = faulty.injected();
  faulty.set_config(FaultConfig{});
  const std::uint64_t accepted_before = link.counters().accepted;
  poll_and_drain(link, run.delivered, [&] { return link.counters().accepted > accepted_before; });
  run.counters = link.counters();
  return run;
}

// The same board and motion with no faults: the truth every delivered sample is compared with.
std::map<std::uint64_t, DeviceSample> clean_samples(std::uint64_t reports) {
  VirtualHostClock clock;
  firmware::Emulator emulator;
  emulator.set_motion(&smooth_motion);
  EmulatorTransport board(emulator, clock);
  DeviceLink link(board, clock);
  std::vector<DeviceSample> delivered;
  poll_and_drain(link, delivered, [&] { return link.counters().accepted >= reports; });
  std::map<std::uint64_t, DeviceSample> by_sequence;
  for (const DeviceSample& s : delivered) {
    if (s.event == LinkEvent::kSample) by_sequence[s.sequence] = s;
  }
  return by_sequence;
}

TEST(FaultInjection, StatisticsCountExactlyWhatWasInjected) {
  constexpr std::uint64_t kReports = 10'000;
  FaultConfig config;
  config.drop_probability = 0.01;
  config.duplicate_probability = 0.005;
  config.corrupt_probability = 0.001;
  config.seed = 20261121;
  const FaultRun run = run_with_faults(config, kReports);
  const InjectedFaults& injected = run.injected;
  const LinkCounters& c = run.counters;

  // The seed gives faults of every kind, near the asked-for rates.
  EXPECT_EQ(injected.passed, kReports);
  EXPECT_GT(injected.dropped, 60u);
  EXPECT_LT(injected.dropped, 140u);
  EXPECT_GT(injected.duplicated, 25u);
  EXPECT_GT(injected.corrupted, 3u);

  // Every report that left the board is accounted for exactly once.
  EXPECT_EQ(c.reports, kReports + 1 - injected.dropped + injected.duplicated);
  EXPECT_EQ(c.duplicates, injected.duplicated);
  EXPECT_EQ(c.rejected, injected.corrupted);
  EXPECT_EQ(c.rejected_by_reason[static_cast<std::size_t>(RejectReason::kCrc)] +
                c.rejected_by_reason[static_cast<std::size_t>(RejectReason::kReportId)] +
                c.rejected_by_reason[static_cast<std::size_t>(RejectReason::kVersion)],
            injected.corrupted);
  // A sequence number is lost when its report was dropped, or arrived corrupt and was turned away.
  EXPECT_EQ(c.lost, injected.dropped + injected.corrupted);
  EXPECT_EQ(c.accepted, kReports + 1 - injected.dropped - injected.corrupted);
  EXPECT_EQ(c.out_of_order, 0u);
  EXPECT_EQ(c.device_time_jumps, 0u);
  EXPECT_EQ(c.disconnects, 0u);
  EXPECT_EQ(c.ring_full, 0u);

  // The consumer got a kConnected and then exactly the accepted samples, strictly in order, each
  // identical to the clean run's sample with the same sequence number.
  ASSERT_FALSE(run.delivered.empty());
  EXPECT_EQ(run.delivered.front().event, LinkEvent::kConnected);
  const auto truth = clean_samples(kReports + 1);
  std::uint64_t samples = 0;
  std::uint64_t previous = 0;
  for (const DeviceSample& s : run.delivered) {
    if (s.event != LinkEvent::kSample) continue;
    if (samples > 0) {
      ASSERT_GT(s.sequence, previous);
    }
    previous = s.sequence;
    ++samples;
    const auto it = truth.find(s.sequence);
    ASSERT_NE(it, truth.end()) << "sequence " << s.sequence;
    const DeviceSample& t = it->second;
    ASSERT_EQ(s.device_time_us, t.device_time_us) << "sequence " << s.sequence;
    ASSERT_EQ(s.joints.yaw_rad, t.joints.yaw_rad);
    ASSERT_EQ(s.joints.pitch_rad, t.joints.pitch_rad);
    ASSERT_EQ(s.joints.roll_rad, t.joints.roll_rad);
    ASSERT_EQ(s.joints.insertion_m, t.joints.insertion_m);
    ASSERT_EQ(s.joints.loop_travel_m, t.joints.loop_travel_m);
    ASSERT_EQ(s.pedals, t.pedals);
    ASSERT_EQ(s.status, t.status);
  }
  EXPECT_EQ(samples, c.accepted);
}

TEST(FaultInjection, DelayedReportsCountAsOutOfOrderNotLost) {
  FaultConfig config;
  config.delay_probability = 0.02;
  config.delay_reports = 3;
  config.seed = 7;
  const FaultRun run = run_with_faults(config, 5'000);
  EXPECT_GT(run.injected.delayed, 50u);
  EXPECT_EQ(run.counters.out_of_order, run.injected.delayed);
  EXPECT_EQ(run.counters.lost, 0u);
  EXPECT_EQ(run.counters.rejected, 0u);
  // Late reports are not delivered: what the consumer sees only moves forward.
  std::uint64_t previous = 0;
  bool first = true;
  for (const DeviceSample& s : run.delivered) {
    if (s.event != LinkEvent::kSample) continue;
    if (!first) {
      ASSERT_GT(s.sequence, previous);
    }
    previous = s.sequence;
    first = false;
  }
  EXPECT_EQ(run.counters.accepted, 5'001 - run.injected.delayed);
}

TEST(FaultInjection, SameSeedSameFaults) {
  FaultConfig config;
  config.drop_probability = 0.05;
  config.duplicate_probability = 0.05;
  config.corrupt_probability = 0.05;
  config.delay_probability = 0.05;
  config.seed = 99;
  const FaultRun a = run_with_faults(config, 2'000);
  const FaultRun b = run_with_faults(config, 2'000);
  EXPECT_EQ(a.injected.dropped, b.injected.dropped);
  EXPECT_EQ(a.injected.corrupted, b.injected.corrupted);
  EXPECT_EQ(a.counters.lost, b.counters.lost);
  EXPECT_EQ(a.counters.rejected, b.counters.rejected);
  ASSERT_EQ(a.delivered.size(), b.delivered.size());
  for (std::size_t i = 0; i < a.delivered.size(); ++i) ASSERT_EQ(a.delivered[i].sequence, b.delivered[i].sequence);
  config.seed = 100;
  const FaultRun c = run_with_faults(config, 2'000);
  EXPECT_NE(a.counters.lost * 1000 + a.counters.rejected, c.counters.lost * 1000 + c.counters.rejected);
}

/// The emulated board behind a fault wrapper that applies `config` to every report, on a virtual clock.
struct FaultyBoard {
  explicit FaultyBoard(const FaultConfig& config) : faulty(board, clock, config) { emulator.set_motion(&smooth_motion); }
  VirtualHostClock clock;
  firmware::Emulator emulator;
  EmulatorTransport board{emulator, clock};
  FaultInjectingTransport faulty;
  std::array<std::uint8_t, kMaxRawReportBytes> buffer{};

  static constexpr std::int64_t kReadTimeoutNs = 20 * kNanosecondsPerMillisecond;
  /// Opens the wrapper (once) and reads one report with kReadTimeoutNs: the read must end within it.
  Result<std::size_t> read_within_timeout() {
    if (!faulty.is_open()) {
      EXPECT_TRUE(faulty.open());
    }
    const std::int64_t start_ns = clock.now_ns();
    Result<std::size_t> got = faulty.read_report(buffer, kReadTimeoutNs);
    EXPECT_LE(clock.now_ns() - start_ns, kReadTimeoutNs + kNanosecondsPerMillisecond);
    return got;
  }
};

TEST(FaultInjection, EveryReportDroppedStillEndsEachReadAtItsTimeout) {
  // A read skipped dropped reports until one came through: with every one dropped it never returned,
  // and `device monitor --drop 1` hung, its link thread never seeing the stop request.
  FaultConfig config;
  config.drop_probability = 1.0;
  FaultyBoard setup(config);
  for (int read = 0; read < 5; ++read) {
    SCOPED_TRACE(read);
    const Result<std::size_t> got = setup.read_within_timeout();
    ASSERT_TRUE(got);
    EXPECT_EQ(*got, 0u) << "nothing gets through";
  }
  EXPECT_GT(setup.faulty.injected().dropped, 50u);
}

TEST(FaultInjection, EveryReportDelayedStillFlowsInOrderWithABoundedBacklog) {
  // Held back until later reports went out, which never happened when all were held: the reads never
  // returned and the queue grew without end. Now they come out late, each once, in the board's order.
  FaultConfig config;
  config.delay_probability = 1.0;
  FaultyBoard setup(config);
  int delivered = 0;
  for (int read = 0; read < 200; ++read) {
    SCOPED_TRACE(read);
    const Result<std::size_t> got = setup.read_within_timeout();
    ASSERT_TRUE(got);
    if (*got > 0) ++delivered;
  }
  EXPECT_GT(delivered, 150) << "most reads deliver a report, late";
  EXPECT_LE(setup.faulty.injected().delayed, static_cast<std::uint64_t>(delivered) + 17u) << "at most the held reports are still waiting";
}

}  // namespace
}  // namespace resecto
