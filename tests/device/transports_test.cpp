// Transports: hidapi really linked and called (no device here: clear errors), recordings written by
// the link's tap replay to the same samples, recording parse errors name the line, and the threaded
// link on the real clock runs at the board's rate with nothing lost.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <thread>

#include "device/link/tool_input.h"
#include "device/transport/emulator_transport.h"
#include "device/transport/hid_transport.h"
#include "device/transport/recorded_transport.h"
#include "resecto/lp3500_protocol.h"
#include "tests/console/run_resecto.h"
#include "tests/device/link_test_support.h"

namespace resecto {
namespace {

using testing::poll_and_drain;
using testing::smooth_motion;

TEST(HidTransport, HidapiIsLinkedAndEnumerates) {
  EXPECT_FALSE(hidapi_version().empty());
  EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(hidapi_version()[0])));
  // Enumerating everything must work whether or not any HID device is attached.
  auto all = enumerate_hid_devices(0, 0);
  ASSERT_TRUE(all.ok()) << all.error();
  for (std::size_t i = 1; i < all->size(); ++i) EXPECT_LE((*all)[i - 1].path, (*all)[i].path);
}

TEST(HidTransport, OpeningWhatIsNotThereSaysWhat) {
  HidSelector by_serial;
  by_serial.vendor_id = LP3500_VENDOR_ID;
  by_serial.product_id = LP3500_PRODUCT_ID;
  by_serial.serial_number = "no-such-serial";
  HidTransport missing(by_serial);
  Status opened = missing.open();
  ASSERT_FALSE(opened.ok());
  EXPECT_NE(opened.error().find("no HID device 1209:3500 with serial no-such-serial found"), std::string::npos)
      << opened.error();
  EXPECT_FALSE(missing.is_open());
  std::array<std::uint8_t, 64> buffer{};
  EXPECT_FALSE(missing.read_report(buffer, 0).ok());

  HidSelector by_path;
  by_path.path = "/nonexistent/hidraw99";
  HidTransport wrong_path(by_path);
  opened = wrong_path.open();
  ASSERT_FALSE(opened.ok());
  EXPECT_NE(opened.error().find("/nonexistent/hidraw99"), std::string::npos) << opened.error();
}

TEST(RecordedTransport, ReplaysTheRecordedBytesToTheSameSamples) {
  const auto dir = resecto::testing::scratch_directory("device_recorded_transport");
  const auto path = dir / "session.rawreports";
  std::vector<DeviceSample> live;
  {
    VirtualHostClock clock;
    firmware::Emulator emulator;
    emulator.set_motion(&smooth_motion);
    EmulatorTransport board(emulator, clock);
    auto writer = RawReportWriter::create(path);
    ASSERT_TRUE(writer.ok()) << writer.error();
    DeviceLink link(board, clock);
    link.set_raw_report_tap([&](std::int64_t host_ns, std::span<const std::uint8_t> bytes) {
      ASSERT_TRUE(writer->write(host_ns, bytes).ok());
    });
    poll_and_drain(link, live, [&] { return link.counters().accepted >= 500; });
    ASSERT_TRUE(writer->finish().ok());
  }
  auto reports = read_raw_reports(path);
  ASSERT_TRUE(reports.ok()) << reports.error();
  ASSERT_EQ(reports->size(), 500u);
  EXPECT_EQ(reports->front().time_us, 0);
  EXPECT_EQ(reports->back().time_us, 499'000);  // one per millisecond of virtual time

  VirtualHostClock clock(123 * kNanosecondsPerSecond);
  RecordedTransport replay(std::move(*reports), clock, path.string());
  DeviceLink link(replay, clock);
  std::vector<DeviceSample> replayed;
  poll_and_drain(link, replayed, [&] { return link.counters().disconnects > 0; });
  EXPECT_NE(link.last_error().find("recording ended after 500 reports"), std::string::npos) << link.last_error();
  EXPECT_EQ(link.counters().accepted, 500u);
  // Both start with kConnected; the replay ends with kDisconnected.
  ASSERT_EQ(replayed.size(), live.size() + 1);
  EXPECT_EQ(replayed.back().event, LinkEvent::kDisconnected);
  for (std::size_t i = 0; i < live.size(); ++i) {
    ASSERT_EQ(replayed[i].event, live[i].event);
    ASSERT_EQ(replayed[i].sequence, live[i].sequence);
    ASSERT_EQ(replayed[i].device_time_us, live[i].device_time_us);
    ASSERT_EQ(replayed[i].joints.insertion_m, live[i].joints.insertion_m);
    ASSERT_EQ(replayed[i].joints.roll_rad, live[i].joints.roll_rad);
    // Replayed with the recorded spacing, shifted to the replay clock's origin (entry 0 is the event).
    if (i > 0) {
      ASSERT_EQ(replayed[i].host_time_ns - replayed[1].host_time_ns, live[i].host_time_ns - live[1].host_time_ns);
    }
  }
}

TEST(RecordedTransport, ParseErrorsNameTheFileAndLine) {
  const auto dir = resecto::testing::scratch_directory("device_recorded_errors");
  const auto check = [&](const std::string& text, const std::string& expected) {
    const auto path = dir / "bad.rawreports";
    std::ofstream(path) << text;
    auto parsed = read_raw_reports(path);
    ASSERT_FALSE(parsed.ok()) << text;
    EXPECT_NE(parsed.error().find(expected), std::string::npos) << parsed.error();
  };
  check("", "bad.rawreports:1: empty file");
  check("hello\n", "bad.rawreports:1: expected the header");
  check("# resecto raw reports v1\n0 0102\n\n5 01zz\n", "bad.rawreports:4: bad hex digit at column 5");
  check("# resecto raw reports v1\n10 01\n5 02\n", "bad.rawreports:3: time 5 us goes backwards");
  check("# resecto raw reports v1\n-3 01\n", "bad.rawreports:2: bad time '-3'");
  check("# resecto raw reports v1\n0 012\n", "bad.rawreports:2: expected 1 to 64 bytes");
  check("# resecto raw reports v1\n0\n", "bad.rawreports:2: expected '<time_us> <hex bytes>'");
  EXPECT_FALSE(read_raw_reports(dir / "missing.rawreports").ok());
}

TEST(DeviceLinkThread, RunsAtTheBoardRateOnTheRealClock) {
  // The link on its own thread, the consumer on this one, through the lock-free ring.
  SteadyHostClock clock;
  firmware::Emulator emulator;
  emulator.set_motion(&smooth_motion);
  EmulatorTransport board(emulator, clock);
  DeviceLink link(board, clock);
  ToolInput tool;
  link.start();
  const std::int64_t start_ns = clock.now_ns();
  std::int64_t last_ns = start_ns;
  std::uint64_t previous_sequence = 0;
  while (clock.now_ns() - start_ns < 400 * kNanosecondsPerMillisecond) {
    const std::int64_t now_ns = clock.now_ns();
    tool.latch(link.samples(), static_cast<double>(now_ns - last_ns) * 1e-9);
    last_ns = now_ns;
    if (tool.samples_latched() > 0) {
      ASSERT_GE(tool.last_sequence(), previous_sequence);
      previous_sequence = tool.last_sequence();
    }
    const LinkCounters published = link.published_counters();  // read while the link writes
    ASSERT_LE(published.accepted, 1'000'000u);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  link.stop();
  tool.latch(link.samples(), 0.0);
  const LinkCounters c = link.counters();
  EXPECT_TRUE(link.published_counters().accepted == c.accepted);
  EXPECT_GT(c.accepted, 250u);
  EXPECT_EQ(c.rejected, 0u);
  EXPECT_EQ(c.duplicates, 0u);
  EXPECT_GT(c.rate_hz, 700.0);
  EXPECT_LT(c.rate_hz, 1300.0);
  EXPECT_EQ(tool.samples_latched(), c.accepted);
  EXPECT_EQ(tool.state(), ToolInputState::kTracking);
}

}  // namespace
}  // namespace resecto
