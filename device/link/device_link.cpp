// The link thread: reconnecting, validating, accounting and handing samples to the core.
#include "device/link/device_link.h"

#include <algorithm>
#include <array>

#include "resecto/lp3500_protocol.h"

namespace resecto {

namespace {
constexpr std::int64_t kPublishIntervalNs = 50 * kNanosecondsPerMillisecond;
}  // namespace

DeviceLink::DeviceLink(DeviceTransport& transport, HostClock& clock, LinkConfig config)
    : transport_(transport), clock_(clock), config_(config), ring_(config.ring_capacity) {
  backoff_ns_ = config_.backoff_initial_ns;
  next_open_ns_ = clock_.now_ns();
}

DeviceLink::~DeviceLink() { stop(); }

void DeviceLink::start() {
  if (thread_.joinable()) return;
  stop_requested_.store(false, std::memory_order_release);
  thread_ = std::thread([this] {
    while (!stop_requested_.load(std::memory_order_acquire)) poll_once();
  });
}

void DeviceLink::stop() {
  if (thread_.joinable()) {
    stop_requested_.store(true, std::memory_order_release);
    thread_.join();
  }
  if (link_up_) {
    transport_.close();
    link_up_ = false;
    connected_.store(false, std::memory_order_release);
  }
  publish(clock_.now_ns(), true);
}

void DeviceLink::set_error(const std::string& message) {
  // Errors are rare (a disconnect, a failed open): blocking briefly here costs the stream nothing.
  std::lock_guard<std::mutex> lock(publish_mutex_);
  last_error_ = message;
}

std::string DeviceLink::last_error() const {
  std::lock_guard<std::mutex> lock(publish_mutex_);
  return last_error_;
}

LinkCounters DeviceLink::published_counters() const {
  std::lock_guard<std::mutex> lock(publish_mutex_);
  return published_;
}

LinkCounters DeviceLink::counters() const {
  LinkCounters snapshot = counters_;
  snapshot.connected = link_up_;
  std::int64_t span_ns = closed_span_ns_;
  std::uint64_t intervals = closed_intervals_;
  if (segment_accepted_ > 1) {
    span_ns += last_accept_ns_ - segment_first_ns_;
    intervals += segment_accepted_ - 1;
  }
  if (span_ns > 0) snapshot.rate_hz = static_cast<double>(intervals) * 1e9 / static_cast<double>(span_ns);
  snapshot.latency_median_us = latency_.quantile(0.5);
  snapshot.latency_p99_us = latency_.quantile(0.99);
  snapshot.latency_max_us = latency_.max();
  return snapshot;
}

void DeviceLink::publish(std::int64_t now_ns, bool force) {
  if (!force && now_ns - last_publish_ns_ < kPublishIntervalNs) return;
  const LinkCounters snapshot = counters();
  // The link thread never waits on a reader: if one holds the lock, publish next time.
  std::unique_lock<std::mutex> lock(publish_mutex_, std::defer_lock);
  if (force) lock.lock();
  else if (!lock.try_lock()) return;
  published_ = snapshot;
  last_publish_ns_ = now_ns;
}

bool DeviceLink::push(const DeviceSample& sample) {
  if (ring_.try_push(sample)) return true;
  ++counters_.ring_full;
  return false;
}

bool DeviceLink::flush_pending_event() {
  // Connection events must reach the core even when the ring was full: retry until they fit.
  if (!have_pending_event_) return true;
  if (!ring_.try_push(pending_event_)) return false;
  have_pending_event_ = false;
  return true;
}

void DeviceLink::try_connect(std::int64_t now_ns) {
  if (now_ns < next_open_ns_) {
    clock_.sleep_until_ns(std::min(next_open_ns_, now_ns + config_.read_timeout_ns));
    return;
  }
  Status opened = transport_.open();
  if (!opened) {
    ++counters_.failed_opens;
    set_error(opened.error());
    next_open_ns_ = now_ns + backoff_ns_;
    backoff_ns_ = std::min(backoff_ns_ * 2, config_.backoff_max_ns);
    return;
  }
  link_up_ = true;
  connected_.store(true, std::memory_order_release);
  ++counters_.connects;
  backoff_ns_ = config_.backoff_initial_ns;
  last_valid_ns_ = now_ns;
  sequence_.reset();
  clock_offset_.reset();
  have_last_sample_ = false;
  // Replaces an undelivered kDisconnected: the core then sees only that the link is up again.
  pending_event_ = DeviceSample{};
  pending_event_.event = LinkEvent::kConnected;
  pending_event_.host_time_ns = now_ns;
  have_pending_event_ = true;
  flush_pending_event();
  publish(now_ns, true);
}

void DeviceLink::disconnect(std::int64_t now_ns, const std::string& reason, bool silence) {
  transport_.close();
  link_up_ = false;
  connected_.store(false, std::memory_order_release);
  ++counters_.disconnects;
  if (silence) ++counters_.silence_timeouts;
  if (segment_accepted_ > 1) {
    closed_span_ns_ += last_accept_ns_ - segment_first_ns_;
    closed_intervals_ += segment_accepted_ - 1;
  }
  segment_accepted_ = 0;
  set_error(reason);
  if (sequence_.has_newest()) {
    have_sequence_before_disconnect_ = true;
    sequence32_before_disconnect_ = sequence_.newest() & 0xFFFFFFFFu;
  }
  pending_event_ = DeviceSample{};
  pending_event_.event = LinkEvent::kDisconnected;
  pending_event_.host_time_ns = now_ns;
  have_pending_event_ = true;
  flush_pending_event();
  next_open_ns_ = now_ns + backoff_ns_;
  backoff_ns_ = std::min(backoff_ns_ * 2, config_.backoff_max_ns);
  publish(now_ns, true);
}

void DeviceLink::poll_once() {
  const std::int64_t now_ns = clock_.now_ns();
  flush_pending_event();
  if (!link_up_) {
    try_connect(now_ns);
    return;
  }
  // Wait no longer than the silence deadline, so a dead device is noticed on time.
  const std::int64_t silence_deadline_ns = last_valid_ns_ + config_.silence_timeout_ns;
  const std::int64_t wait_ns = std::clamp<std::int64_t>(silence_deadline_ns - now_ns, 0, config_.read_timeout_ns);
  std::array<std::uint8_t, kMaxRawReportBytes> buffer{};
  Result<std::size_t> got = transport_.read_report(buffer, wait_ns);
  const std::int64_t host_ns = clock_.now_ns();
  if (!got) {
    disconnect(host_ns, got.error(), false);
    return;
  }
  if (*got > 0) handle_report(host_ns, std::span<const std::uint8_t>(buffer.data(), *got));
  if (host_ns - last_valid_ns_ >= config_.silence_timeout_ns) {
    disconnect(host_ns,
               transport_.describe() + ": no valid report for " +
                   std::to_string((host_ns - last_valid_ns_) / kNanosecondsPerMillisecond) + " ms",
               true);
    return;
  }
  publish(host_ns, false);
}

void DeviceLink::handle_report(std::int64_t host_ns, std::span<const std::uint8_t> bytes) {
  ++counters_.reports;
  if (tap_) tap_(host_ns, bytes);
  DecodedReport decoded = decode_input_report(bytes, config_.calibration);
  if (!decoded.valid) {
    ++counters_.rejected;
    ++counters_.rejected_by_reason[static_cast<std::size_t>(decoded.reason)];
    return;
  }
  std::uint64_t unwrapped = 0;
  std::uint64_t gap = 0;
  const SequenceVerdict verdict = sequence_.observe(decoded.sequence32, unwrapped, gap);
  switch (verdict) {
    case SequenceVerdict::kDuplicate:
      ++counters_.duplicates;
      last_valid_ns_ = host_ns;
      return;
    case SequenceVerdict::kLate:
      // It was counted lost when the newer one came; it is late, not lost. Too old to deliver.
      if (counters_.lost > 0) --counters_.lost;
      ++counters_.out_of_order;
      last_valid_ns_ = host_ns;
      return;
    case SequenceVerdict::kStale:
      ++counters_.rejected;
      ++counters_.rejected_by_reason[static_cast<std::size_t>(RejectReason::kStaleSequence)];
      return;
    case SequenceVerdict::kRestart:
      ++counters_.sequence_restarts;
      have_last_sample_ = false;
      break;
    case SequenceVerdict::kFirst:
      if (have_sequence_before_disconnect_) {
        counters_.missed_while_disconnected +=
            static_cast<std::uint32_t>(decoded.sequence32 - static_cast<std::uint32_t>(sequence32_before_disconnect_)) - 1u;
        have_sequence_before_disconnect_ = false;
      }
      break;
    case SequenceVerdict::kNext:
      counters_.lost += gap;
      break;
  }

  DeviceSample& sample = decoded.sample;
  // The tracker counts from one wrap up; delivered samples are never older than the first one.
  sample.sequence = unwrapped - (std::uint64_t{1} << 32);
  sample.host_time_ns = host_ns;
  if (have_last_sample_) {
    const std::uint64_t expected_us = (unwrapped - last_sequence_) * config_.report_period_us;
    const bool backwards = sample.device_time_us < last_device_time_us_;
    const std::uint64_t actual_us = backwards ? 0 : sample.device_time_us - last_device_time_us_;
    const std::uint64_t error_us = actual_us > expected_us ? actual_us - expected_us : expected_us - actual_us;
    if (backwards || error_us * 2 > config_.report_period_us) ++counters_.device_time_jumps;
  }
  have_last_sample_ = true;
  last_sequence_ = unwrapped;
  last_device_time_us_ = sample.device_time_us;
  last_valid_ns_ = host_ns;
  latency_.add(clock_offset_.observe(host_ns, sample.device_time_us));
  if (segment_accepted_++ == 0) segment_first_ns_ = host_ns;
  last_accept_ns_ = host_ns;
  ++counters_.accepted;
  counters_.board_flags.count(sample.status);
  if (flush_pending_event()) push(sample);
  else ++counters_.ring_full;
}

}  // namespace resecto
