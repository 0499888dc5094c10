// The shared protocol header: CRC check value, every report field round-trips, any corrupted byte or
// wrong length/id/version is refused, and the HID descriptor declares the sizes the header packs.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <map>

#include "resecto/lp3500_protocol.h"
#include "resecto/lp3500_sensors.h"

namespace {

lp3500_input_report sample_report() {
  lp3500_input_report r{};
  r.sequence = 0xDEADBEEFu;
  r.device_time_us = 0x0123456789ABCDEFull;
  r.encoder_counts[0] = -123456789;
  r.encoder_counts[1] = 2147483647;
  r.encoder_counts[2] = -2147483647 - 1;
  r.sheath_um = 229999;
  r.loop_um = -1;
  r.adc_potentiometer = 4095;
  r.adc_hall_a = 1234;
  r.adc_hall_b = 3210;
  r.pedals = LP3500_PEDAL_CUT | LP3500_PEDAL_COAGULATE;
  r.status = LP3500_STATUS_ILLEGAL_ENCODER_2 | LP3500_STATUS_STALL | LP3500_STATUS_NO_ADC_SAMPLE;
  r.illegal_transitions[0] = 1;
  r.illegal_transitions[1] = 0xFFFF;
  r.illegal_transitions[2] = 0x8001;
  r.adc_samples = 0xA5A5;
  r.ring_high_water = 8192;
  return r;
}

TEST(Lp3500Protocol, Crc16CcittFalseCheckValue) {
  const char* text = "123456789";
  EXPECT_EQ(lp3500_crc16(reinterpret_cast<const uint8_t*>(text), 9), 0x29B1);
}

TEST(Lp3500Protocol, InputReportRoundTripsEveryField) {
  const lp3500_input_report in = sample_report();
  std::array<uint8_t, LP3500_INPUT_REPORT_SIZE> bytes{};
  lp3500_pack_input_report(&in, bytes.data());
  EXPECT_EQ(bytes[0], LP3500_REPORT_ID_INPUT);
  EXPECT_EQ(bytes[1], LP3500_PROTOCOL_VERSION);
  // Little-endian at the documented offsets (README table).
  EXPECT_EQ(bytes[2], 0xEF);
  EXPECT_EQ(bytes[5], 0xDE);
  EXPECT_EQ(bytes[6], 0xEF);
  EXPECT_EQ(bytes[13], 0x01);
  EXPECT_EQ(bytes[22], 0x00);
  EXPECT_EQ(bytes[25], 0x80);
  EXPECT_EQ(bytes[40], 3);
  for (int i = 54; i < 62; ++i) EXPECT_EQ(bytes[i], 0) << "reserved byte " << i;
  lp3500_input_report out{};
  ASSERT_EQ(lp3500_unpack_input_report(bytes.data(), bytes.size(), &out), LP3500_OK);
  EXPECT_EQ(out.sequence, in.sequence);
  EXPECT_EQ(out.device_time_us, in.device_time_us);
  for (int e = 0; e < 3; ++e) {
    EXPECT_EQ(out.encoder_counts[e], in.encoder_counts[e]);
    EXPECT_EQ(out.illegal_transitions[e], in.illegal_transitions[e]);
  }
  EXPECT_EQ(out.sheath_um, in.sheath_um);
  EXPECT_EQ(out.loop_um, in.loop_um);
  EXPECT_EQ(out.adc_potentiometer, in.adc_potentiometer);
  EXPECT_EQ(out.adc_hall_a, in.adc_hall_a);
  EXPECT_EQ(out.adc_hall_b, in.adc_hall_b);
  EXPECT_EQ(out.pedals, in.pedals);
  EXPECT_EQ(out.status, in.status);
  EXPECT_EQ(out.adc_samples, in.adc_samples);
  EXPECT_EQ(out.ring_high_water, in.ring_high_water);
}

TEST(Lp3500Protocol, EveryCorruptedByteIsRefused) {
  const lp3500_input_report in = sample_report();
  std::array<uint8_t, LP3500_INPUT_REPORT_SIZE> good{};
  lp3500_pack_input_report(&in, good.data());
  for (size_t i = 0; i < good.size(); ++i) {
    auto bad = good;
    bad[i] ^= 0x10;
    lp3500_input_report out{};
    const lp3500_result expected = i == 0 ? LP3500_ERROR_REPORT_ID : i == 1 ? LP3500_ERROR_VERSION : LP3500_ERROR_CRC;
    EXPECT_EQ(lp3500_unpack_input_report(bad.data(), bad.size(), &out), expected) << "byte " << i;
  }
  lp3500_input_report out{};
  EXPECT_EQ(lp3500_unpack_input_report(good.data(), good.size() - 1, &out), LP3500_ERROR_LENGTH);
}

TEST(Lp3500Protocol, IdentityRoundTrips) {
  lp3500_identity in{};
  in.firmware_major = 1;
  in.firmware_minor = 2;
  in.firmware_patch = 3;
  in.serial_number = 0xCAFEF00Du;
  in.report_rate_hz = 1000;
  in.adc_rate_hz = 4000;
  in.encoder_poll_rate_hz = 40000;
  in.max_stall_ms = 100;
  in.edge_ring_capacity = 8192;
  in.calibration_crc = 0xBEEF;
  in.calibration_written = 1;
  std::strcpy(in.name, "Resecto LP3500");
  std::array<uint8_t, LP3500_IDENTITY_REPORT_SIZE> bytes{};
  lp3500_pack_identity(&in, bytes.data());
  lp3500_identity out{};
  ASSERT_EQ(lp3500_unpack_identity(bytes.data(), bytes.size(), &out), LP3500_OK);
  EXPECT_EQ(std::memcmp(&in, &out, sizeof in), 0);
}

TEST(Lp3500Protocol, CalibrationRoundTripsAndRefusesNonMonotoneTables) {
  lp3500_calibration in = lp3500_default_calibration;
  std::array<uint8_t, LP3500_CALIBRATION_REPORT_SIZE> bytes{};
  lp3500_pack_calibration(&in, 0, bytes.data());
  lp3500_calibration out{};
  uint8_t status = 99;
  ASSERT_EQ(lp3500_unpack_calibration(bytes.data(), bytes.size(), &out, &status), LP3500_OK);
  EXPECT_EQ(status, 0);
  EXPECT_EQ(std::memcmp(&in, &out, sizeof in), 0);

  lp3500_calibration bad = in;
  bad.hall_sum[40] = bad.hall_sum[39];  // flat step: not strictly monotone
  int index = -2;
  EXPECT_EQ(lp3500_validate_calibration(&bad, &index), LP3500_ERROR_NOT_MONOTONE);
  EXPECT_EQ(index, 40);
  lp3500_pack_calibration(&bad, 0, bytes.data());
  EXPECT_EQ(lp3500_unpack_calibration(bytes.data(), bytes.size(), &out, nullptr), LP3500_ERROR_NOT_MONOTONE);

  bad = in;
  bad.sheath_gain_nm_per_count = 0;
  EXPECT_EQ(lp3500_validate_calibration(&bad, nullptr), LP3500_ERROR_SHEATH_RANGE);

  // A decreasing table is monotone too.
  lp3500_calibration falling = in;
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) falling.hall_sum[i] = static_cast<uint16_t>(9000 - in.hall_sum[i]);
  EXPECT_EQ(lp3500_validate_calibration(&falling, nullptr), LP3500_OK);
}

// Walks the short items of the descriptor and adds up each report id's payload bits.
TEST(Lp3500Protocol, DescriptorDeclaresTheHeaderSizes) {
  const uint8_t* d = lp3500_report_descriptor;
  const size_t n = sizeof lp3500_report_descriptor;
  uint32_t usage_page = 0, report_size = 0, report_count = 0, report_id = 0;
  std::map<std::pair<int, uint32_t>, uint32_t> bits;  // (main item tag, id) -> bits
  for (size_t i = 0; i < n;) {
    const uint8_t prefix = d[i];
    const size_t size = (prefix & 3u) == 3u ? 4u : (prefix & 3u);
    uint32_t value = 0;
    for (size_t k = 0; k < size; ++k) value |= uint32_t{d[i + 1 + k]} << (8 * k);
    switch (prefix & 0xFCu) {
      case 0x04: usage_page = value; break;
      case 0x74: report_size = value; break;
      case 0x94: report_count = value; break;
      case 0x84: report_id = value; break;
      case 0x80: case 0xB0: bits[{prefix & 0xFC, report_id}] += report_size * report_count; break;
      default: break;
    }
    i += 1 + size;
  }
  EXPECT_EQ(usage_page, 0xFF00u);
  EXPECT_EQ((bits[{0x80, LP3500_REPORT_ID_INPUT}] / 8 + 1), LP3500_INPUT_REPORT_SIZE);
  EXPECT_EQ((bits[{0xB0, LP3500_REPORT_ID_IDENTITY}] / 8 + 1), LP3500_IDENTITY_REPORT_SIZE);
  EXPECT_EQ((bits[{0xB0, LP3500_REPORT_ID_CALIBRATION}] / 8 + 1), LP3500_CALIBRATION_REPORT_SIZE);
}

}  // namespace
