// Deterministic fault injection between a transport and the link.
#include "device/transport/fault_injection.h"

#include <algorithm>

namespace resecto {

std::uint64_t SplitMix64::next() {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double SplitMix64::uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

std::uint64_t SplitMix64::below(std::uint64_t n) { return n == 0 ? 0 : next() % n; }

FaultInjectingTransport::FaultInjectingTransport(DeviceTransport& inner, HostClock& clock, FaultConfig config)
    : inner_(inner), clock_(clock), config_(config), random_(config.seed) {}

std::string FaultInjectingTransport::describe() const { return inner_.describe() + " (with injected faults)"; }

void FaultInjectingTransport::set_config(const FaultConfig& config) { config_ = config; }

bool FaultInjectingTransport::unplugged() const { return clock_.now_ns() < unplugged_until_ns_; }

void FaultInjectingTransport::unplug_now() {
  ++injected_.unplugged;
  unplugged_until_ns_ = clock_.now_ns() + config_.unplug_duration_ns;
  pending_.clear();  // whatever was in flight is lost with the cable
  inner_.close();
  open_ = false;
}

Status FaultInjectingTransport::open() {
  if (unplugged()) return Error{describe() + ": device unplugged (injected)"};
  Status status = inner_.open();
  open_ = status.ok();
  return status;
}

void FaultInjectingTransport::close() {
  pending_.clear();
  inner_.close();
  open_ = false;
}

bool FaultInjectingTransport::deliver_pending(std::span<std::uint8_t> buffer, std::size_t& length) {
  if (pending_.empty() || pending_.front().release_after > 0) return false;
  const HeldReport& held = pending_.front();
  length = std::min(held.length, buffer.size());
  std::copy_n(held.bytes.begin(), length, buffer.begin());
  pending_.pop_front();
  on_report_delivered();
  return true;
}

void FaultInjectingTransport::on_report_delivered() {
  // Every report handed out brings each delayed report one step closer to release.
  for (HeldReport& held : pending_) held.release_after = std::max(0, held.release_after - 1);
}

Result<std::size_t> FaultInjectingTransport::read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) {
  if (!open_) return Error{describe() + ": not open"};
  std::size_t length = 0;
  if (deliver_pending(buffer, length)) return length;

  // Dropped and delayed reports are read past within this call, but never past its timeout: with
  // every report dropped (or held back) the loop would otherwise never return, and the link thread
  // that called it would never see its stop request (`device monitor --drop 1` hung).
  const std::int64_t deadline_ns = clock_.now_ns() + std::max<std::int64_t>(timeout_ns, 0);
  for (bool first = true;; first = false) {
    if (config_.unplug_probability > 0.0 && random_.uniform() < config_.unplug_probability) unplug_now();
    if (!open_) return Error{describe() + ": device unplugged (injected)"};

    std::array<std::uint8_t, kMaxRawReportBytes> bytes{};
    const std::int64_t remaining_ns = deadline_ns - clock_.now_ns();
    Result<std::size_t> got = first || remaining_ns > 0 ? inner_.read_report(bytes, std::max<std::int64_t>(remaining_ns, 0)) : Result<std::size_t>{0};
    if (!got) return got;
    if (*got == 0) {
      // Silence from the device releases what is held back rather than keeping it forever.
      for (HeldReport& held : pending_) held.release_after = 0;
      if (deliver_pending(buffer, length)) return length;
      return std::size_t{0};
    }
    ++injected_.passed;
    HeldReport report;
    report.length = std::min(*got, bytes.size());
    report.bytes = bytes;

    // One draw picks at most one fault, so each report's fate is unambiguous to count.
    const double u = random_.uniform();
    double edge = config_.drop_probability;
    if (u < edge) {
      ++injected_.dropped;
      continue;  // read the next one within the same call, as if this one never existed
    }
    if (u < (edge += config_.corrupt_probability)) {
      ++injected_.corrupted;
      const std::uint64_t bit = random_.below(report.length * 8);
      report.bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    } else if (u < (edge += config_.duplicate_probability)) {
      ++injected_.duplicated;
      pending_.push_front(report);  // the copy goes out on the next read
      pending_.front().release_after = 0;
    } else if (u < (edge += config_.delay_probability)) {
      ++injected_.delayed;
      report.release_after = std::max(1, config_.delay_reports);
      pending_.push_back(report);
      // Held back for later ones that, when every report is delayed, never go out: past a few
      // reports' worth the oldest goes out now, late, rather than the queue growing without end.
      if (pending_.size() > kMaxHeldReports) {
        pending_.front().release_after = 0;
        if (deliver_pending(buffer, length)) return length;
      }
      continue;  // this read returns the next report instead
    }
    length = std::min(report.length, buffer.size());
    std::copy_n(report.bytes.begin(), length, buffer.begin());
    on_report_delivered();
    return length;
  }
}

Result<std::size_t> FaultInjectingTransport::get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) {
  if (!open_) return Error{describe() + ": not open"};
  return inner_.get_feature_report(report_id, buffer);
}

Status FaultInjectingTransport::send_feature_report(std::span<const std::uint8_t> report) {
  if (!open_) return Error{describe() + ": not open"};
  return inner_.send_feature_report(report);
}

}  // namespace resecto
