// DeviceLink: the link thread between a transport and the core. It reads raw reports, validates and
// converts each into a DeviceSample, pushes in-order samples into a bounded lock-free SPSC ring, and
// keeps the link's statistics. A transport error, or no valid report for `silence_timeout_ns`
// (documented default: 100 ms, i.e. 100 missed reports at 1 kHz), means disconnected: the core gets a
// kDisconnected entry in order, and the link reopens the transport by itself with exponential backoff
// (20 ms doubling to 1 s), announcing kConnected before the next sample.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <thread>

#include "device/link/device_sample.h"
#include "device/link/link_statistics.h"
#include "device/link/report_decoder.h"
#include "device/link/sequence_tracker.h"
#include "device/transport/device_transport.h"
#include "device/transport/host_clock.h"
#include "rtcore/base/timing_histogram.h"
#include "rtcore/concurrency/spsc_ring.h"

namespace resecto {

/// Timing and conversion settings of the link.
struct LinkConfig {
  JointCalibration calibration;
  std::int64_t silence_timeout_ns = 100 * kNanosecondsPerMillisecond;  ///< no valid report this long: disconnected
  std::int64_t read_timeout_ns = 10 * kNanosecondsPerMillisecond;      ///< longest single wait in the transport
  std::int64_t backoff_initial_ns = 20 * kNanosecondsPerMillisecond;   ///< first wait before reopening
  std::int64_t backoff_max_ns = 1000 * kNanosecondsPerMillisecond;     ///< the wait doubles up to this
  std::uint64_t report_period_us = 1000;  ///< the board's report period, for device-time jump checks
  std::size_t ring_capacity = 4096;       ///< samples the core may fall behind by (4 s at 1 kHz)
};

/// Called on the link thread with every raw report read (before validation), e.g. to record it.
using RawReportTap = std::function<void(std::int64_t host_time_ns, std::span<const std::uint8_t> bytes)>;

/// The link. Either start() its own thread, or call poll_once() from one thread (tests, batch runs).
class DeviceLink {
 public:
  DeviceLink(DeviceTransport& transport, HostClock& clock, LinkConfig config = {});
  ~DeviceLink();
  DeviceLink(const DeviceLink&) = delete;
  DeviceLink& operator=(const DeviceLink&) = delete;

  /// Runs poll_once() on a new thread until stop().
  void start();
  /// Stops and joins the thread (if running), closes the transport and publishes final statistics.
  void stop();

  /// One step: open if due, else read one report (or time out) and handle it.
  void poll_once();

  /// The consumer's end of the ring (consumer thread only).
  SpscRing<DeviceSample>& samples() { return ring_; }

  /// Statistics as last published by the link thread (about every 50 ms, and at stop()); any thread.
  LinkCounters published_counters() const;
  /// Statistics computed now: only from the thread that polls, or after stop().
  LinkCounters counters() const;
  /// Whether the device is connected (any thread).
  bool connected() const { return connected_.load(std::memory_order_acquire); }
  /// The last transport error or disconnect reason (any thread).
  std::string last_error() const;

  /// Install before start(): sees every raw report on the link thread.
  void set_raw_report_tap(RawReportTap tap) { tap_ = std::move(tap); }
  const LinkConfig& config() const { return config_; }

 private:
  void try_connect(std::int64_t now_ns);
  void disconnect(std::int64_t now_ns, const std::string& reason, bool silence);
  void handle_report(std::int64_t host_ns, std::span<const std::uint8_t> bytes);
  bool push(const DeviceSample& sample);
  bool flush_pending_event();
  void publish(std::int64_t now_ns, bool force);
  void set_error(const std::string& message);

  DeviceTransport& transport_;
  HostClock& clock_;
  LinkConfig config_;
  SpscRing<DeviceSample> ring_;
  RawReportTap tap_;

  // Link-thread state.
  LinkCounters counters_;
  TimingHistogram latency_;
  ClockOffsetEstimator clock_offset_;
  SequenceTracker sequence_;
  bool link_up_ = false;
  bool have_pending_event_ = false;
  DeviceSample pending_event_;
  std::int64_t next_open_ns_ = 0;
  std::int64_t backoff_ns_ = 0;
  std::int64_t last_valid_ns_ = 0;
  // Rate over connected time only: spans between first and last sample of each connection.
  std::int64_t segment_first_ns_ = 0;
  std::int64_t last_accept_ns_ = 0;
  std::uint64_t segment_accepted_ = 0;
  std::int64_t closed_span_ns_ = 0;
  std::uint64_t closed_intervals_ = 0;
  std::int64_t last_publish_ns_ = 0;
  std::uint64_t last_sequence_ = 0;        ///< unwrapped, of the last accepted sample
  std::uint64_t last_device_time_us_ = 0;
  bool have_last_sample_ = false;
  bool have_sequence_before_disconnect_ = false;
  std::uint64_t sequence32_before_disconnect_ = 0;

  // Shared with other threads.
  std::atomic<bool> connected_{false};
  std::atomic<bool> stop_requested_{false};
  mutable std::mutex publish_mutex_;  ///< guards published_ and last_error_; the link thread only try_locks
  LinkCounters published_;
  std::string last_error_;
  std::thread thread_;
};

}  // namespace resecto
