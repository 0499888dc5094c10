// `resecto device list|monitor` end to end: the clear line when no device is attached, the emulator's
// live link with its JSON summary (and injected faults counted in it), recordings, and bad arguments.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/console/run_resecto.h"

namespace resecto::testing {
namespace {

std::size_t line_count(const std::string& text) {
  std::size_t n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

TEST(DeviceCommand, ListWithNoDeviceSaysSoAndHowToUseTheEmulator) {
  const CommandOutput r = run_resecto("device list");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("no LP3500 HID device 1209:3500 found"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--device emulator"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(DeviceCommand, ListHonoursOtherIds) {
  const CommandOutput r = run_resecto("device list --vid 0x1234 --pid 0x5678");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("1234:5678"), std::string::npos) << r.err;
}

TEST(DeviceCommand, MonitorOnHidWithNoDeviceFailsWithTheSameLine) {
  const CommandOutput r = run_resecto("device monitor --device hid --seconds 0.2");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("--device emulator"), std::string::npos) << r.err;
}

TEST(DeviceCommand, MonitorOnTheEmulatorEndsWithAJsonSummary) {
  const CommandOutput r = run_resecto("device monitor --device emulator --seconds 0.5 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"reports", "lost", "duplicates", "rejected", "rate_hz", "latency_us"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_TRUE(j["latency_us"].contains("median"));
  EXPECT_TRUE(j["latency_us"].contains("p99"));
  EXPECT_GT(j["reports"].get<int>(), 250);  // about 500 at 1 kHz; leave room for a loaded machine
  EXPECT_EQ(j["lost"].get<int>(), 0);
  EXPECT_EQ(j["rejected"].get<int>(), 0);
  EXPECT_GT(j["rate_hz"].get<double>(), 500.0);
  EXPECT_LE(j["latency_us"]["median"].get<double>(), j["latency_us"]["p99"].get<double>());
  // The identity feature report was read through the same transport.
  ASSERT_TRUE(j["identity"].is_object()) << j.dump();
  EXPECT_EQ(j["identity"]["report_rate_hz"].get<int>(), 1000);
}

TEST(DeviceCommand, MonitorCountsTheFaultsItInjects) {
  const CommandOutput r =
      run_resecto("device monitor --device emulator --seconds 0.6 --drop 0.02 --duplicate 0.01 --corrupt 0.01 --seed 5 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto injected = j["injected"];
  EXPECT_GT(injected["dropped"].get<int>(), 0);
  EXPECT_EQ(j["duplicates"], injected["duplicated"]);
  EXPECT_EQ(j["rejected"], injected["corrupted"]);
  // Lost = dropped + corrupted, except that faults on the very last reports leave no gap behind them.
  const int expected_lost = injected["dropped"].get<int>() + injected["corrupted"].get<int>();
  EXPECT_LE(j["lost"].get<int>(), expected_lost);
  EXPECT_GE(j["lost"].get<int>() + 3, expected_lost);
}

TEST(DeviceCommand, MonitorPrintsLiveLinesAndRecords) {
  const auto dir = scratch_directory("device_monitor_record");
  const auto path = dir / "session.rawreports";
  const CommandOutput r = run_resecto("device monitor --device emulator --seconds 0.6 --record " + path.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("connected"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tip ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rate"), std::string::npos) << r.out;
  const std::string recorded = read_text(path);
  EXPECT_EQ(recorded.rfind("# resecto raw reports v1\n", 0), 0u);
  EXPECT_GT(line_count(recorded), 300u);
}

TEST(DeviceCommand, BadArgumentsFailWithAReason) {
  CommandOutput r = run_resecto("device monitor --device serial");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--device"), std::string::npos) << r.err;
  r = run_resecto("device monitor --device emulator --drop 1.5");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--drop"), std::string::npos) << r.err;
  r = run_resecto("device monitor --device emulator --seconds 0.1 --drop 0.6 --corrupt 0.6");
  EXPECT_EQ(r.exit_code, 2) << "options that cannot be run together: a command-line error";
  EXPECT_NE(r.err.find("probability"), std::string::npos) << r.err;
  r = run_resecto("device monitor --device emulator --seconds 0.1 --calibration /nonexistent/cal.json");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("/nonexistent/cal.json"), std::string::npos) << r.err;
  EXPECT_EQ(run_resecto("device monitor --help").exit_code, 0);
  EXPECT_EQ(run_resecto("device list --help").exit_code, 0);
}

}  // namespace
}  // namespace resecto::testing
