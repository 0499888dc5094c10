// Recorded raw reports: a plain text file of timestamped HID input reports, written by the monitor
// and replayed through RecordedTransport with the original timing, so a session's exact bytes
// (including any malformed ones) can be fed to the link again.
//
// Format (version 1): the first line is `# resecto raw reports v1`; then one report per line,
// `<host time, microseconds from the first report> <bytes as hex, two digits each>`. Blank lines
// and other lines starting with `#` are ignored.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <fstream>
#include <string>
#include <vector>

#include "device/transport/device_transport.h"
#include "device/transport/host_clock.h"
#include "rtcore/base/atomic_file.h"

namespace resecto {

inline constexpr const char* kRawReportsHeader = "# resecto raw reports v1";

/// One report as recorded.
struct RecordedReport {
  std::int64_t time_us = 0;  ///< host receive time relative to the first report
  std::vector<std::uint8_t> bytes;
};

/// Parses a whole recording; errors name the file and line.
Result<std::vector<RecordedReport>> read_raw_reports(const std::filesystem::path& path);

/// Appends reports to a recording as they arrive. Not for the real-time path (it does I/O). The
/// recording appears at its path only when finish() succeeds (AtomicFile); a write failure at any
/// point is kept and reported by finish().
class RawReportWriter {
 public:
  /// Starts the recording for `path` and writes the header line.
  static Result<RawReportWriter> create(const std::filesystem::path& path);
  /// Writes one report received at `host_time_ns` (the first call fixes the time origin).
  Status write(std::int64_t host_time_ns, std::span<const std::uint8_t> bytes);
  /// Writes what is buffered and puts the recording in place; the first failure if any write failed.
  Status finish();

  RawReportWriter(RawReportWriter&&) = default;
  RawReportWriter& operator=(RawReportWriter&&) = default;

 private:
  RawReportWriter() = default;
  std::unique_ptr<AtomicFile> file_;
  std::string pending_;  // written out in blocks, not a system call per report
  std::int64_t origin_ns_ = 0;
  bool has_origin_ = false;
};

/// Replays a recording through `clock`, each report released at its recorded offset from open().
/// The end of the recording reads as a disconnection, and it cannot be reopened after that.
class RecordedTransport final : public DeviceTransport {
 public:
  RecordedTransport(std::vector<RecordedReport> reports, HostClock& clock, std::string name = "recording");

  Status open() override;
  void close() override { open_ = false; }
  bool is_open() const override { return open_; }
  Result<std::size_t> read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) override;
  Result<std::size_t> get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) override;
  Status send_feature_report(std::span<const std::uint8_t> report) override;
  std::string describe() const override { return "recorded reports " + name_; }

  /// Reports handed out so far.
  std::size_t position() const { return next_; }

 private:
  std::vector<RecordedReport> reports_;
  HostClock& clock_;
  std::string name_;
  std::int64_t start_ns_ = 0;
  std::size_t next_ = 0;
  bool open_ = false;
  bool started_ = false;
};

}  // namespace resecto
