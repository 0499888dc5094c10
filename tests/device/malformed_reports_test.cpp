// A million malformed reports through the decoder and the link: no crash, no undefined behaviour
// (run under the sanitizers), and each one rejected with the reason an independent check predicts
// (length, then report id, then version, then CRC, in the protocol's order).
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <numbers>
#include <vector>

#include "device/link/device_link.h"
#include "device/link/report_decoder.h"
#include "device/transport/fault_injection.h"
#include "resecto/lp3500_protocol.h"

namespace resecto {
namespace {

// CRC-16/CCITT-FALSE from a 256-entry table: a second implementation to judge the protocol header's.
std::uint16_t reference_crc(const std::uint8_t* data, std::size_t length) {
  static const auto table = [] {
    std::array<std::uint16_t, 256> t{};
    for (unsigned i = 0; i < 256; ++i) {
      std::uint16_t crc = static_cast<std::uint16_t>(i << 8);
      for (int bit = 0; bit < 8; ++bit) {
        crc = (crc & 0x8000u) ? static_cast<std::uint16_t>((crc << 1) ^ 0x1021u) : static_cast<std::uint16_t>(crc << 1);
      }
      t[i] = crc;
    }
    return t;
  }();
  std::uint16_t crc = 0xFFFF;
  for (std::size_t i = 0; i < length; ++i) {
    crc = static_cast<std::uint16_t>((crc << 8) ^ table[((crc >> 8) ^ data[i]) & 0xFFu]);
  }
  return crc;
}

TEST(ReferenceCrc, MatchesTheCheckValue) {
  const char* text = "123456789";
  EXPECT_EQ(reference_crc(reinterpret_cast<const std::uint8_t*>(text), 9), 0x29B1);
  EXPECT_EQ(lp3500_crc16(reinterpret_cast<const std::uint8_t*>(text), 9), 0x29B1);
}

/// What the protocol says is wrong with `bytes`, checked in its order; kOk when nothing is.
enum class Expected { kOk, kLength, kReportId, kVersion, kCrc };

Expected judge(const std::uint8_t* bytes, std::size_t length) {
  if (length != LP3500_INPUT_REPORT_SIZE) return Expected::kLength;
  if (bytes[0] != LP3500_REPORT_ID_INPUT) return Expected::kReportId;
  if (bytes[1] != LP3500_PROTOCOL_VERSION) return Expected::kVersion;
  const std::uint16_t sent = static_cast<std::uint16_t>(bytes[62] | (bytes[63] << 8));
  if (sent != reference_crc(bytes, 62)) return Expected::kCrc;
  return Expected::kOk;
}

RejectReason reason_for(Expected e) {
  switch (e) {
    case Expected::kLength: return RejectReason::kLength;
    case Expected::kReportId: return RejectReason::kReportId;
    case Expected::kVersion: return RejectReason::kVersion;
    default: return RejectReason::kCrc;
  }
}

/// Produces malformed reports of many kinds from a seed, on demand (no stored million).
class MalformedReportSource final : public DeviceTransport {
 public:
  explicit MalformedReportSource(std::uint64_t seed) : random_(seed) {}

  Status open() override { open_ = true; return Ok{}; }
  void close() override { open_ = false; }
  bool is_open() const override { return open_; }
  Result<std::size_t> get_feature_report(std::uint8_t, std::span<std::uint8_t>) override { return Error{"none"}; }
  Status send_feature_report(std::span<const std::uint8_t>) override { return Error{"none"}; }
  std::string describe() const override { return "malformed report source"; }

  Result<std::size_t> read_report(std::span<std::uint8_t> buffer, std::int64_t) override {
    std::size_t length = 0;
    do {
      length = make(buffer);
    } while (judge(buffer.data(), length) == Expected::kOk);  // astronomically rare for the random kinds
    expected_[static_cast<std::size_t>(reason_for(judge(buffer.data(), length)))]++;
    ++made_;
    return length;
  }

  std::array<std::uint64_t, kRejectReasonCount> expected_{};
  std::uint64_t made_ = 0;

 private:
  std::size_t make(std::span<std::uint8_t> buffer) {
    // A valid report of random content to start the mutated kinds from.
    lp3500_input_report r{};
    r.sequence = static_cast<std::uint32_t>(random_.next());
    r.device_time_us = random_.next();
    for (auto& count : r.encoder_counts) count = static_cast<std::int32_t>(random_.next());
    r.sheath_um = static_cast<std::int32_t>(random_.next());
    r.loop_um = static_cast<std::int32_t>(random_.next());
    r.pedals = static_cast<std::uint8_t>(random_.next());
    r.status = static_cast<std::uint16_t>(random_.next());
    std::uint8_t valid[LP3500_INPUT_REPORT_SIZE];
    lp3500_pack_input_report(&r, valid);
    std::memcpy(buffer.data(), valid, sizeof valid);

    switch (random_.below(7)) {
      // Lengths start at 1: a read of 0 bytes is "nothing arrived", not a report, in hidapi as here.
      case 0: {  // any other length, random bytes
        const std::size_t length = 1 + random_.below(LP3500_INPUT_REPORT_SIZE - 1);
        for (std::size_t i = 0; i < length; ++i) buffer[i] = static_cast<std::uint8_t>(random_.next());
        return length;
      }
      case 1:  // a valid report cut short
        return 1 + random_.below(LP3500_INPUT_REPORT_SIZE - 1);
      case 2:  // 1..3 bit flips anywhere (CRC-16/CCITT has Hamming distance 4 at this length)
        for (std::uint64_t flips = 1 + random_.below(3); flips > 0; --flips) {
          const std::uint64_t bit = random_.below(LP3500_INPUT_REPORT_SIZE * 8);
          buffer[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
        }
        return LP3500_INPUT_REPORT_SIZE;
      case 3:  // wrong report id (a feature report's, or anything)
        buffer[0] = static_cast<std::uint8_t>(random_.below(2) ? LP3500_REPORT_ID_IDENTITY : random_.next());
        return LP3500_INPUT_REPORT_SIZE;
      case 4:  // another protocol version, correctly sealed otherwise
        buffer[1] = static_cast<std::uint8_t>(random_.next());
        lp3500_put_u16(buffer.data() + 62, lp3500_crc16(buffer.data(), 62));
        return LP3500_INPUT_REPORT_SIZE;
      case 5:  // right header, random body and CRC
        for (std::size_t i = 2; i < LP3500_INPUT_REPORT_SIZE; ++i) buffer[i] = static_cast<std::uint8_t>(random_.next());
        return LP3500_INPUT_REPORT_SIZE;
      default:  // a valid report whose CRC bytes were damaged in transit
        buffer[62 + random_.below(2)] ^= static_cast<std::uint8_t>(1 + random_.below(255));
        return LP3500_INPUT_REPORT_SIZE;
    }
  }

  SplitMix64 random_;
  bool open_ = false;
};

TEST(MalformedReports, AMillionThroughTheLinkAreAllRejectedWithTheRightReason) {
  constexpr std::uint64_t kReports = 1'000'000;
  VirtualHostClock clock;  // never advanced by the source: no silence timeout can fire
  MalformedReportSource source(424242);
  DeviceLink link(source, clock);
  while (source.made_ < kReports) link.poll_once();
  const LinkCounters c = link.counters();
  EXPECT_EQ(c.reports, kReports);
  EXPECT_EQ(c.rejected, kReports);
  EXPECT_EQ(c.accepted, 0u);
  EXPECT_EQ(c.duplicates + c.lost + c.out_of_order, 0u);
  for (int r = 1; r < kRejectReasonCount; ++r) {
    EXPECT_EQ(c.rejected_by_reason[static_cast<std::size_t>(r)], source.expected_[static_cast<std::size_t>(r)])
        << reject_reason_name(static_cast<RejectReason>(r));
  }
  // Every framing reason occurred many times.
  for (RejectReason r : {RejectReason::kLength, RejectReason::kReportId, RejectReason::kVersion, RejectReason::kCrc}) {
    EXPECT_GT(c.rejected_by_reason[static_cast<std::size_t>(r)], 50'000u) << reject_reason_name(r);
  }
  // Only the kConnected event reached the consumer.
  DeviceSample entry;
  ASSERT_TRUE(link.samples().try_pop(entry));
  EXPECT_EQ(entry.event, LinkEvent::kConnected);
  EXPECT_FALSE(link.samples().try_pop(entry));
}

TEST(MalformedReports, DecoderReadsOnlyInsideItsSpan) {
  // Exact-size heap copies, so AddressSanitizer catches any read past the end at every length.
  SplitMix64 random(5);
  for (std::size_t length = 0; length <= 130; ++length) {
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<std::uint8_t> bytes(length);
      for (auto& b : bytes) b = static_cast<std::uint8_t>(random.next());
      if (length >= 2 && trial % 2 == 0) {
        bytes[0] = LP3500_REPORT_ID_INPUT;
        bytes[1] = LP3500_PROTOCOL_VERSION;
      }
      const DecodedReport decoded = decode_input_report(bytes, JointCalibration{});
      ASSERT_FALSE(decoded.valid) << "length " << length;
      ASSERT_EQ(decoded.reason, reason_for(judge(bytes.data(), bytes.size()))) << "length " << length;
    }
  }
}

TEST(MalformedReports, AValidReportDecodesToSiUnits) {
  lp3500_input_report r{};
  r.sequence = 77;
  r.device_time_us = 123456789;
  r.encoder_counts[0] = 1024;   // a quarter turn at 4096 counts/rev
  r.encoder_counts[1] = -512;
  r.encoder_counts[2] = 2048;
  r.sheath_um = 172'500;
  r.loop_um = 12'000;
  r.pedals = LP3500_PEDAL_CUT;
  r.status = LP3500_STATUS_STALL;
  std::uint8_t bytes[LP3500_INPUT_REPORT_SIZE];
  lp3500_pack_input_report(&r, bytes);
  const DecodedReport decoded = decode_input_report(bytes, JointCalibration{});
  ASSERT_TRUE(decoded.valid);
  EXPECT_EQ(decoded.sequence32, 77u);
  EXPECT_EQ(decoded.sample.device_time_us, 123456789u);
  EXPECT_DOUBLE_EQ(decoded.sample.joints.yaw_rad, std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(decoded.sample.joints.pitch_rad, -std::numbers::pi / 4);
  EXPECT_DOUBLE_EQ(decoded.sample.joints.roll_rad, std::numbers::pi);
  EXPECT_DOUBLE_EQ(decoded.sample.joints.insertion_m, 0.1725);
  EXPECT_DOUBLE_EQ(decoded.sample.joints.loop_travel_m, 0.012);
  EXPECT_EQ(decoded.sample.pedals, kPedalCut);
  EXPECT_EQ(decoded.sample.status, LP3500_STATUS_STALL);
}

}  // namespace
}  // namespace resecto
