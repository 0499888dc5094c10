// `resecto device list` and `resecto device monitor`: the HID devices that match, and the live link
// (from the LP3500 or the in-process emulator, optionally through injected faults) with its
// statistics; `--json` ends with one summary object. `device calibrate` lives in its own file.
#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "console/commands/checked_options.h"
#include "console/commands/command_registry.h"
#include "device/calibration/calibration.h"
#include "device/link/calibration_adapter.h"
#include "device/link/device_link.h"
#include "device/link/tool_input.h"
#include "device/transport/fault_injection.h"
#include "device/transport/hid_transport.h"
#include "device/transport/recorded_transport.h"
#include "resecto/lp3500_protocol.h"
#include "rtcore/base/units.h"
#ifdef RESECTO_HAVE_EMULATOR
#include "device/input/sweep_motion.h"
#include "device/transport/emulator_transport.h"
#endif

namespace resecto::cli {
namespace {

constexpr const char* kFamilyDescription = "Device tools: list, monitor and calibrate the LP3500 resectoscope interface";


std::string hex4(unsigned value) {
  char text[8];
  std::snprintf(text, sizeof text, "%04x", value);
  return text;
}

/// Vendor/product ids and which device, shared by list and monitor.
struct HidOptions {
  unsigned vendor_id = LP3500_VENDOR_ID;
  unsigned product_id = LP3500_PRODUCT_ID;
  std::string path;
  std::string serial;
};

void add_hid_options(CLI::App& cmd, HidOptions& hid) {
  cmd.add_option("--vid", hid.vendor_id, "USB vendor id (default 0x1209)")->check(CLI::Range(0u, 0xFFFFu));
  cmd.add_option("--pid", hid.product_id, "USB product id (default 0x3500)")->check(CLI::Range(0u, 0xFFFFu));
  cmd.add_option("--path", hid.path, "Open this hidraw node instead of the first match");
  cmd.add_option("--serial", hid.serial, "Open the match with this serial number");
}

std::string none_found_line(const HidOptions& hid) {
  return "no LP3500 HID device " + hex4(hid.vendor_id) + ":" + hex4(hid.product_id) +
         " found (hidapi " + hidapi_version() +
         "); to run without hardware use: resecto device monitor --device emulator";
}

void register_list(CLI::App& family) {
  auto hid = std::make_shared<HidOptions>();
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = family.add_subcommand("list", "List the HID devices matching the LP3500's vendor and product ids");
  add_hid_options(*cmd, *hid);
  cmd->add_flag("--json", *json, "Print the list as JSON");
  cmd->callback([hid, json] {
    auto devices = enumerate_hid_devices(static_cast<std::uint16_t>(hid->vendor_id),
                                         static_cast<std::uint16_t>(hid->product_id));
    if (!devices) fail(devices.error());
    if (devices->empty()) fail(none_found_line(*hid));
    nlohmann::json list = nlohmann::json::array();
    for (const HidDeviceInfo& d : *devices) {
      if (*json) {
        list.push_back({{"path", d.path}, {"vendor_id", hex4(d.vendor_id)}, {"product_id", hex4(d.product_id)},
                        {"serial", d.serial_number}, {"manufacturer", d.manufacturer}, {"product", d.product},
                        {"release", d.release_number}, {"interface", d.interface_number}});
      } else {
        std::printf("%s  %s:%s  serial %s  %s %s\n", d.path.c_str(), hex4(d.vendor_id).c_str(),
                    hex4(d.product_id).c_str(), d.serial_number.c_str(), d.manufacturer.c_str(), d.product.c_str());
      }
    }
    if (*json) std::printf("%s\n", list.dump(2).c_str());
  });
}

struct MonitorOptions {
  std::string device = "hid";
  double seconds = 5.0;
  double drop = 0.0;
  double duplicate = 0.0;
  double corrupt = 0.0;
  double delay = 0.0;
  double unplug = 0.0;
  std::uint64_t seed = 1;
  bool json = false;
  std::string record;
  std::string calibration;
  HidOptions hid;
};


nlohmann::json summary_json(const MonitorOptions& o, const LinkCounters& c, const InjectedFaults& injected,
                            const std::string& description, double seconds) {
  nlohmann::json by_reason = nlohmann::json::object();
  for (int r = 1; r < kRejectReasonCount; ++r) {
    by_reason[reject_reason_name(static_cast<RejectReason>(r))] = c.rejected_by_reason[static_cast<std::size_t>(r)];
  }
  return {{"device", o.device},
          {"transport", description},
          {"seconds", seconds},
          {"reports", c.reports},
          {"accepted", c.accepted},
          {"lost", c.lost},
          {"duplicates", c.duplicates},
          {"out_of_order", c.out_of_order},
          {"rejected", c.rejected},
          {"rejected_by_reason", by_reason},
          {"device_time_jumps", c.device_time_jumps},
          {"sequence_restarts", c.sequence_restarts},
          {"missed_while_disconnected", c.missed_while_disconnected},
          {"connects", c.connects},
          {"disconnects", c.disconnects},
          {"silence_timeouts", c.silence_timeouts},
          {"rate_hz", c.rate_hz},
          {"latency_us", {{"median", c.latency_median_us}, {"p99", c.latency_p99_us}, {"max", c.latency_max_us}}},
          {"injected",
           {{"dropped", injected.dropped},
            {"duplicated", injected.duplicated},
            {"corrupted", injected.corrupted},
            {"delayed", injected.delayed},
            {"unplugged", injected.unplugged}}}};
}

void check_probability(double p, const char* name) {
  // Options that cannot be run together: a command-line error, exit 2 (audit 8, G11).
  if (!(p >= 0.0 && p <= 1.0)) refuse_command_line(std::string("--") + name + " must be a probability in [0, 1]");
}

void run_monitor(const MonitorOptions& o) {
  check_probability(o.drop + o.duplicate + o.corrupt + o.delay, "drop + --duplicate + --corrupt + --delay");
  SteadyHostClock clock;
  std::unique_ptr<DeviceTransport> transport;
#ifdef RESECTO_HAVE_EMULATOR
  std::unique_ptr<firmware::Emulator> emulator;
#endif
  if (o.device == "hid") {
    if (o.hid.path.empty()) {
      auto devices = enumerate_hid_devices(static_cast<std::uint16_t>(o.hid.vendor_id),
                                           static_cast<std::uint16_t>(o.hid.product_id));
      if (!devices) fail(devices.error());
      if (devices->empty()) fail(none_found_line(o.hid));
    }
    if (!o.hid.path.empty()) {
      if (Status node = check_hidraw_node(o.hid.path); !node) fail(node.error());
    }
    HidSelector selector;
    selector.vendor_id = static_cast<std::uint16_t>(o.hid.vendor_id);
    selector.product_id = static_cast<std::uint16_t>(o.hid.product_id);
    selector.path = o.hid.path;
    selector.serial_number = o.hid.serial;
    transport = std::make_unique<HidTransport>(selector);
  } else {
#ifdef RESECTO_HAVE_EMULATOR
    firmware::EmulatorOptions emulator_options;
    emulator_options.seed = o.seed;
    emulator = std::make_unique<firmware::Emulator>(emulator_options);
    emulator->set_motion(&sweep_motion);
    transport = std::make_unique<EmulatorTransport>(*emulator, clock);
#else
    fail("this build has no emulator (firmware_emulator was not built)");
#endif
  }

  device::Calibration calibration = device::default_calibration();
  if (!o.calibration.empty()) {
    auto read = device::read_calibration(o.calibration);
    if (!read) fail(read.error());
    calibration = *read;
  }
  LinkConfig link_config;
  link_config.calibration = joint_calibration_from(calibration);
  const GimbalGeometry geometry = gimbal_geometry_from(calibration);

  FaultConfig faults;
  faults.drop_probability = o.drop;
  faults.duplicate_probability = o.duplicate;
  faults.corrupt_probability = o.corrupt;
  faults.delay_probability = o.delay;
  faults.unplug_probability = o.unplug;
  faults.seed = o.seed;
  FaultInjectingTransport faulty(*transport, clock, faults);

  // The board's identity, read once before the link thread takes the transport over.
  nlohmann::json identity = nullptr;
  if (Status opened = faulty.open(); opened) {
    std::array<std::uint8_t, LP3500_IDENTITY_REPORT_SIZE> bytes{};
    auto got = faulty.get_feature_report(LP3500_REPORT_ID_IDENTITY, bytes);
    lp3500_identity id{};
    if (got && lp3500_unpack_identity(bytes.data(), *got, &id) == LP3500_OK) {
      identity = {{"name", std::string(id.name)},
                  {"firmware", std::to_string(id.firmware_major) + "." + std::to_string(id.firmware_minor) + "." +
                                   std::to_string(id.firmware_patch)},
                  {"serial_number", id.serial_number},
                  {"report_rate_hz", id.report_rate_hz},
                  {"calibration_written", id.calibration_written != 0}};
    }
    faulty.close();
  }

  std::optional<RawReportWriter> recorder;
  if (!o.record.empty()) {
    auto created = RawReportWriter::create(o.record);
    if (!created) fail(created.error());
    recorder.emplace(std::move(*created));
  }

  DeviceLink link(faulty, clock, link_config);
  if (recorder) {
    // The recorder runs on the link thread; a monitor is not the real-time path, so its I/O is fine.
    link.set_raw_report_tap([&recorder](std::int64_t host_ns, std::span<const std::uint8_t> bytes) {
      (void)recorder->write(host_ns, bytes);
    });
  }
  ToolInput tool;
  const std::int64_t start_ns = clock.now_ns();
  const std::int64_t end_ns = start_ns + static_cast<std::int64_t>(o.seconds * 1e9);
  std::int64_t last_tick_ns = start_ns;
  std::int64_t next_print_ns = start_ns + 250 * kNanosecondsPerMillisecond;
  link.start();
  if (!o.json) {
    std::printf("monitoring %s for %.1f s\n", faulty.describe().c_str(), o.seconds);
    if (!identity.is_null()) std::printf("board: %s\n", identity.dump().c_str());
  }
  for (;;) {
    const std::int64_t now_ns = clock.now_ns();
    if (now_ns >= end_ns) break;
    tool.latch(link.samples(), static_cast<double>(now_ns - last_tick_ns) * 1e-9);
    last_tick_ns = now_ns;
    if (!o.json && now_ns >= next_print_ns) {
      next_print_ns += 250 * kNanosecondsPerMillisecond;
      const LinkCounters c = link.published_counters();
      const DeviceJoints& j = tool.joints();
      const Vec3 tip_mm = sheath_tip_world(j, geometry) * units::kMillimetresPerMetre;
      std::printf("%7.2f s %-12s seq %8llu  yaw %6.1f pitch %6.1f roll %6.1f deg  sheath %6.1f loop %5.1f mm  %s"
                  "  tip (%6.1f %6.1f %6.1f) mm  | %6.0f Hz lost %llu dup %llu rej %llu\n",
                  static_cast<double>(now_ns - start_ns) * 1e-9, c.connected ? "connected" : "DISCONNECTED",
                  static_cast<unsigned long long>(tool.last_sequence()), units::rad_to_deg(j.yaw_rad),
                  units::rad_to_deg(j.pitch_rad), units::rad_to_deg(j.roll_rad), units::m_to_mm(j.insertion_m),
                  units::m_to_mm(j.loop_travel_m), (tool.pedals() & kPedalCut) ? "CUT" : "   ", tip_mm.x, tip_mm.y,
                  tip_mm.z, c.rate_hz,
                  static_cast<unsigned long long>(c.lost), static_cast<unsigned long long>(c.duplicates),
                  static_cast<unsigned long long>(c.rejected));
      std::fflush(stdout);
    }
    clock.sleep_until_ns(std::min(end_ns, now_ns + 5 * kNanosecondsPerMillisecond));
  }
  link.stop();
  if (recorder) {
    if (Status finished = recorder->finish(); !finished) fail(finished.error());
  }
  tool.latch(link.samples(), 0.0);
  const LinkCounters c = link.counters();
  const double seconds = static_cast<double>(clock.now_ns() - start_ns) * 1e-9;
  if (c.connects == 0) fail("the device never connected: " + link.last_error());
  nlohmann::json summary = summary_json(o, c, faulty.injected(), faulty.describe(), seconds);
  summary["identity"] = identity;
  if (o.json) {
    std::printf("%s\n", summary.dump(2).c_str());
  } else {
    std::printf("reports %llu accepted %llu lost %llu duplicates %llu out-of-order %llu rejected %llu "
                "time-jumps %llu disconnects %llu\nrate %.1f Hz  latency median %.1f us  p99 %.1f us  max %.1f us\n",
                static_cast<unsigned long long>(c.reports), static_cast<unsigned long long>(c.accepted),
                static_cast<unsigned long long>(c.lost), static_cast<unsigned long long>(c.duplicates),
                static_cast<unsigned long long>(c.out_of_order), static_cast<unsigned long long>(c.rejected),
                static_cast<unsigned long long>(c.device_time_jumps),
                static_cast<unsigned long long>(c.disconnects), c.rate_hz, c.latency_median_us, c.latency_p99_us,
                c.latency_max_us);
  }
}

void register_monitor(CLI::App& family) {
  auto o = std::make_shared<MonitorOptions>();
  CLI::App* cmd = family.add_subcommand("monitor", "Show the live device link and its statistics");
  cmd->add_option("--device", o->device, "Where reports come from")
      ->check(CLI::IsMember({"hid", "emulator"}))->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "How long to monitor")->check(finite_range(0.01, 86400.0))->capture_default_str();
  cmd->add_option("--drop", o->drop, "Inject: probability a report is dropped")->check(finite_range(0.0, 1.0));
  cmd->add_option("--duplicate", o->duplicate, "Inject: probability a report arrives twice")->check(finite_range(0.0, 1.0));
  cmd->add_option("--corrupt", o->corrupt, "Inject: probability one bit of a report flips")->check(finite_range(0.0, 1.0));
  cmd->add_option("--delay", o->delay, "Inject: probability a report arrives late (out of order)")->check(finite_range(0.0, 1.0));
  cmd->add_option("--unplug", o->unplug, "Inject: probability per read that the cable is pulled for 300 ms")
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--seed", o->seed, "Seed of the injected faults and the emulator's noise")->check(unsigned_64())->capture_default_str();
  cmd->add_option("--calibration", o->calibration, "Calibration file (JSON; default: the board's compiled-in one)");
  cmd->add_option("--record", o->record, "Write every raw report to this file (text, timestamped)")->check(nonempty_path());
  cmd->add_flag("--json", o->json, "Print only a JSON summary at the end");
  add_hid_options(*cmd, o->hid);
  cmd->callback([o] { run_monitor(*o); });
}

void register_device_commands(CLI::App& app) {
  CLI::App& family = subcommand_family(app, "device", kFamilyDescription);
  register_list(family);
  register_monitor(family);
}

}  // namespace

static const RegisterCommand kRegister{"device", &register_device_commands};

}  // namespace resecto::cli
