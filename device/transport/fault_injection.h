// FaultInjectingTransport: wraps any transport and, from a seeded generator, drops, duplicates,
// corrupts, delays reports or simulates an unplug, counting every fault it injects so tests can check
// that the link's statistics see exactly what happened. Same seed and same input: same faults.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <vector>

#include "device/transport/device_transport.h"
#include "device/transport/host_clock.h"

namespace resecto {

/// Per-report fault probabilities (each report suffers at most one of drop/duplicate/corrupt/delay)
/// and the unplug model.
struct FaultConfig {
  double drop_probability = 0.0;       ///< report never arrives
  double duplicate_probability = 0.0;  ///< report arrives twice in a row
  double corrupt_probability = 0.0;    ///< one bit of the report flipped
  double delay_probability = 0.0;      ///< report held back and delivered after `delay_reports` later ones
  int delay_reports = 2;
  double unplug_probability = 0.0;     ///< per report read: the device goes away
  std::int64_t unplug_duration_ns = 300 * kNanosecondsPerMillisecond;  ///< open() fails until then
  std::uint64_t seed = 1;
};

/// What was injected so far.
struct InjectedFaults {
  std::uint64_t passed = 0;       ///< reports read from the inner transport
  std::uint64_t dropped = 0;
  std::uint64_t duplicated = 0;
  std::uint64_t corrupted = 0;
  std::uint64_t delayed = 0;
  std::uint64_t unplugged = 0;
};

/// splitmix64: a tiny, well-mixed generator whose output is the same on every platform (the standard
/// library's distributions are not).
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  /// Uniform in [0, 1) with 53 random bits.
  double uniform();
  /// Uniform in [0, n) for n > 0.
  std::uint64_t below(std::uint64_t n);

 private:
  std::uint64_t state_;
};

/// The wrapper. Feature reports pass through untouched (while plugged in).
class FaultInjectingTransport final : public DeviceTransport {
 public:
  FaultInjectingTransport(DeviceTransport& inner, HostClock& clock, FaultConfig config);

  Status open() override;
  void close() override;
  bool is_open() const override { return open_; }
  Result<std::size_t> read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) override;
  Result<std::size_t> get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) override;
  Status send_feature_report(std::span<const std::uint8_t> report) override;
  std::string describe() const override;

  /// Changes the rates from now on (the generator's state carries on).
  void set_config(const FaultConfig& config);
  /// Unplugs now, as if the cable were pulled, for the configured duration.
  void unplug_now();
  const InjectedFaults& injected() const { return injected_; }
  /// True while a simulated unplug lasts.
  bool unplugged() const;

 private:
  struct HeldReport {
    std::array<std::uint8_t, kMaxRawReportBytes> bytes{};
    std::size_t length = 0;
    int release_after = 0;  ///< deliver once this many later reports have gone out (delay); 0 = next
  };

  bool deliver_pending(std::span<std::uint8_t> buffer, std::size_t& length);
  void on_report_delivered();

  DeviceTransport& inner_;
  HostClock& clock_;
  FaultConfig config_;
  SplitMix64 random_;
  InjectedFaults injected_;
  /// Delayed reports held at once, at most: a delay of a few reports, not a growing backlog.
  static constexpr std::size_t kMaxHeldReports = 16;
  std::deque<HeldReport> pending_;  ///< duplicates and delayed reports waiting their turn
  std::int64_t unplugged_until_ns_ = -1;
  bool open_ = false;
};

}  // namespace resecto
