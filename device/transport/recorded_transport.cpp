// Reading, writing and replaying the text recording of raw HID reports.
#include "device/transport/recorded_transport.h"

#include <cerrno>
#include <cstdlib>
#include <sstream>

#include "rtcore/base/text_file.h"

namespace resecto {
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

Result<std::vector<RecordedReport>> read_raw_reports(const std::filesystem::path& path) {
  // Read whole and capped: a device such as /dev/zero has no line end and no end.
  Result<std::string> text = read_text_file(path, " the recording");
  if (!text) return Error{text.error()};
  std::istringstream in(*text);
  std::vector<RecordedReport> reports;
  std::string line;
  int line_number = 0;
  bool saw_header = false;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string where = path.string() + ":" + std::to_string(line_number) + ": ";
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!saw_header) {
      if (line != kRawReportsHeader) {
        return Error{where + "expected the header '" + std::string(kRawReportsHeader) + "'"};
      }
      saw_header = true;
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    const std::size_t space = line.find(' ');
    if (space == std::string::npos) return Error{where + "expected '<time_us> <hex bytes>'"};
    const std::string time_text = line.substr(0, space);
    char* end = nullptr;
    errno = 0;
    const long long time_us = std::strtoll(time_text.c_str(), &end, 10);
    if (time_text.empty() || *end != '\0' || errno != 0 || time_us < 0) {
      return Error{where + "bad time '" + time_text + "' (non-negative microseconds)"};
    }
    if (!reports.empty() && time_us < reports.back().time_us) {
      return Error{where + "time " + time_text + " us goes backwards"};
    }
    const std::string hex = line.substr(space + 1);
    if (hex.empty() || hex.size() % 2 != 0 || hex.size() / 2 > kMaxRawReportBytes) {
      return Error{where + "expected 1 to " + std::to_string(kMaxRawReportBytes) + " bytes as pairs of hex digits"};
    }
    RecordedReport report;
    report.time_us = time_us;
    for (std::size_t i = 0; i < hex.size(); i += 2) {
      const int high = hex_digit(hex[i]);
      const int low = hex_digit(hex[i + 1]);
      if (high < 0 || low < 0) {
        return Error{where + "bad hex digit at column " + std::to_string(space + 2 + i + (high < 0 ? 0 : 1))};
      }
      report.bytes.push_back(static_cast<std::uint8_t>(high * 16 + low));
    }
    reports.push_back(std::move(report));
  }
  if (!saw_header) return Error{path.string() + ":1: empty file, expected the header '" + kRawReportsHeader + "'"};
  return reports;
}

Result<RawReportWriter> RawReportWriter::create(const std::filesystem::path& path) {
  RawReportWriter writer;
  writer.file_ = std::make_unique<AtomicFile>();
  if (Status opened = writer.file_->open(path); !opened) return Error{opened.error()};
  writer.pending_ = std::string(kRawReportsHeader) + '\n';
  return writer;
}

Status RawReportWriter::write(std::int64_t host_time_ns, std::span<const std::uint8_t> bytes) {
  if (!has_origin_) {
    origin_ns_ = host_time_ns;
    has_origin_ = true;
  }
  static constexpr char kHex[] = "0123456789abcdef";
  pending_ += std::to_string((host_time_ns - origin_ns_) / kNanosecondsPerMicrosecond);
  pending_ += ' ';
  for (std::uint8_t b : bytes) {
    pending_ += kHex[b >> 4];
    pending_ += kHex[b & 15];
  }
  pending_ += '\n';
  if (pending_.size() < (std::size_t{1} << 16)) return Ok{};
  Status written = file_->write(pending_);
  pending_.clear();
  return written;
}

Status RawReportWriter::finish() {
  Status written = file_->write(pending_);
  pending_.clear();
  if (!written) {
    file_->discard();
    return written;
  }
  return file_->commit();
}

RecordedTransport::RecordedTransport(std::vector<RecordedReport> reports, HostClock& clock, std::string name)
    : reports_(std::move(reports)), clock_(clock), name_(std::move(name)) {}

Status RecordedTransport::open() {
  if (next_ >= reports_.size() && started_) return Error{describe() + ": recording ended"};
  if (!started_) {
    // Replay times are offsets from the first open; reopening resumes where it left off.
    start_ns_ = clock_.now_ns() - (reports_.empty() ? 0 : reports_.front().time_us * kNanosecondsPerMicrosecond);
    started_ = true;
  }
  open_ = true;
  return Ok{};
}

Result<std::size_t> RecordedTransport::read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) {
  if (!open_) return Error{describe() + ": not open"};
  if (next_ >= reports_.size()) {
    open_ = false;
    return Error{describe() + ": recording ended after " + std::to_string(reports_.size()) + " reports"};
  }
  const RecordedReport& report = reports_[next_];
  const std::int64_t due_ns = start_ns_ + report.time_us * kNanosecondsPerMicrosecond;
  const std::int64_t now_ns = clock_.now_ns();
  if (due_ns > now_ns + timeout_ns) {
    clock_.sleep_until_ns(now_ns + timeout_ns);
    return std::size_t{0};
  }
  clock_.sleep_until_ns(due_ns);
  if (report.bytes.size() > buffer.size()) return Error{describe() + ": report larger than the read buffer"};
  std::copy(report.bytes.begin(), report.bytes.end(), buffer.begin());
  ++next_;
  return report.bytes.size();
}

Result<std::size_t> RecordedTransport::get_feature_report(std::uint8_t report_id, std::span<std::uint8_t>) {
  return Error{describe() + ": feature report " + std::to_string(report_id) + " is not recorded"};
}

Status RecordedTransport::send_feature_report(std::span<const std::uint8_t>) {
  return Error{describe() + ": a recording takes no feature reports"};
}

}  // namespace resecto
