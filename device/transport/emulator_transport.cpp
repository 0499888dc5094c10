// The emulator behind the transport interface, paced by the host clock.
#include "device/transport/emulator_transport.h"

#include <algorithm>
#include <deque>

namespace resecto {

namespace {
constexpr std::uint64_t kStepUs = 1000;  // one report period: the finest pacing the host can see
}  // namespace

EmulatorTransport::EmulatorTransport(firmware::Emulator& emulator, HostClock& clock)
    : emulator_(emulator), clock_(clock) {}

std::uint64_t EmulatorTransport::device_time_at(std::int64_t host_ns) const {
  return host_ns <= origin_ns_ ? 0 : static_cast<std::uint64_t>((host_ns - origin_ns_) / kNanosecondsPerMicrosecond);
}

void EmulatorTransport::discard_until(std::uint64_t device_time_us) {
  while (emulator_.time_us() + kStepUs <= device_time_us) emulator_.advance(kStepUs);
  while (emulator_.read_input_report()) {
  }
}

Status EmulatorTransport::open() {
  const std::int64_t now_ns = clock_.now_ns();
  if (!started_) {
    origin_ns_ = now_ns - static_cast<std::int64_t>(emulator_.time_us()) * kNanosecondsPerMicrosecond;
    started_ = true;
  } else {
    // The board ran on while the host was away; what it sent meanwhile is gone.
    discard_until(device_time_at(now_ns));
  }
  open_ = true;
  return Ok{};
}

Result<std::size_t> EmulatorTransport::read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) {
  if (!open_) return Error{describe() + ": not open"};
  if (buffer.size() < LP3500_INPUT_REPORT_SIZE) return Error{describe() + ": read buffer smaller than a report"};
  const std::int64_t now_ns = clock_.now_ns();
  // If the host fell far behind, the reports older than a host queue's worth are lost (overwritten).
  const std::uint64_t now_device_us = device_time_at(now_ns);
  const std::uint64_t queue_span_us = kEmulatedHostQueueReports * kStepUs;
  if (now_device_us > emulator_.time_us() + queue_span_us) {
    discard_until(now_device_us - queue_span_us);
  }
  const std::int64_t deadline_ns = now_ns + std::max<std::int64_t>(timeout_ns, 0);
  for (;;) {
    if (auto report = emulator_.read_input_report()) {
      std::copy(report->begin(), report->end(), buffer.begin());
      return std::size_t{LP3500_INPUT_REPORT_SIZE};
    }
    // The next period ends at this host time; wait for it unless that is past the timeout.
    const std::int64_t due_ns =
        origin_ns_ + static_cast<std::int64_t>(emulator_.time_us() + kStepUs) * kNanosecondsPerMicrosecond;
    if (due_ns > deadline_ns) {
      clock_.sleep_until_ns(deadline_ns);
      return std::size_t{0};
    }
    clock_.sleep_until_ns(due_ns);
    emulator_.advance(kStepUs);
  }
}

Result<std::size_t> EmulatorTransport::get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) {
  if (!open_) return Error{describe() + ": not open"};
  const std::vector<std::uint8_t> bytes = emulator_.get_feature_report(report_id);
  if (bytes.empty()) return Error{describe() + ": no feature report " + std::to_string(report_id)};
  if (bytes.size() > buffer.size()) {
    return Error{describe() + ": feature report " + std::to_string(report_id) + " needs " +
                 std::to_string(bytes.size()) + " bytes"};
  }
  std::copy(bytes.begin(), bytes.end(), buffer.begin());
  return bytes.size();
}

Status EmulatorTransport::send_feature_report(std::span<const std::uint8_t> report) {
  if (!open_) return Error{describe() + ": not open"};
  const lp3500_result result = emulator_.set_feature_report(report.data(), report.size());
  if (result != LP3500_OK) {
    return Error{describe() + ": board refused feature report: " + lp3500_result_name(result)};
  }
  return Ok{};
}

}  // namespace resecto
