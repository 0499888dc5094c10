// The firmware driven by the emulator's sensor models: the sheath's linear model and the loop's Hall
// table against the true travel, clamping, lossless stalls of the main loop, feature reports,
// determinism, and the board's RAM and table sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <vector>

#include "firmware/emulator/lp3500_emulator.h"
#include "resecto/lp3500_board.h"
#include "resecto/lp3500_sensors.h"

namespace {

using resecto::firmware::Emulator;
using resecto::firmware::EmulatorOptions;
using resecto::firmware::MotionState;
using resecto::firmware::SensorModel;

EmulatorOptions options(uint64_t seed) {
  EmulatorOptions o;
  o.seed = seed;
  return o;
}

std::vector<lp3500_input_report> drain(Emulator& emulator) {
  std::vector<lp3500_input_report> reports;
  while (auto bytes = emulator.read_input_report()) {
    lp3500_input_report r{};
    EXPECT_EQ(lp3500_unpack_input_report(bytes->data(), bytes->size(), &r), LP3500_OK);
    reports.push_back(r);
  }
  return reports;
}

/// Advances in 10 ms steps, taking reports as the host link would (the board queues 256).
std::vector<lp3500_input_report> run_for(Emulator& emulator, uint64_t duration_us) {
  std::vector<lp3500_input_report> reports;
  for (uint64_t done = 0; done < duration_us; done += 10'000) {
    emulator.advance(std::min<uint64_t>(10'000, duration_us - done));
    for (const auto& r : drain(emulator)) reports.push_back(r);
  }
  return reports;
}

/// Mean of `f` over the four ADC sample times of report `sequence` (ticks 0, 10, 20, 30 of its period).
template <class F>
double mean_over_adc_samples(uint32_t sequence, F f) {
  double sum = 0.0;
  for (unsigned k = 0; k < 4; ++k) {
    sum += f((uint64_t{sequence} * LP3500_REPORT_TICKS + k * LP3500_ADC_TICKS) * LP3500_TICK_US);
  }
  return sum / 4.0;
}

TEST(Emulator, FirmwareDefaultHallTableIsTheReferenceMagnetModel) {
  const lp3500_calibration nominal = resecto::firmware::nominal_calibration(SensorModel{});
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    EXPECT_EQ(nominal.hall_sum[i], lp3500_default_calibration.hall_sum[i]) << "point " << i;
    EXPECT_EQ(nominal.loop_um[i], lp3500_default_calibration.loop_um[i]) << "point " << i;
  }
  EXPECT_EQ(lp3500_validate_calibration(&lp3500_default_calibration, nullptr), LP3500_OK);
}

TEST(Emulator, LoopFollowsTheHallModelWithinHalfAMillimetreAcrossTheTravel) {
  Emulator emulator(options(5));
  const double sweep_us = 4e6;  // 0 -> 36.5 mm in 4 s, with 2 mV RMS noise on each Hall channel
  auto loop_mm = [&](uint64_t t) { return std::min(36.5, 36.5 * static_cast<double>(t) / sweep_us); };
  emulator.set_motion([&](uint64_t t) { return MotionState{.insertion_mm = 100.0, .loop_mm = loop_mm(t)}; });
  const auto reports = run_for(emulator, 4'000'000);
  ASSERT_EQ(reports.size(), 4000u);
  double worst_mm = 0.0;
  for (const auto& r : reports) {
    const double truth = mean_over_adc_samples(r.sequence, loop_mm);
    worst_mm = std::max(worst_mm, std::abs(r.loop_um * 1e-3 - truth));
    EXPECT_EQ(r.status & LP3500_STATUS_LOOP_CLAMPED, 0) << "sequence " << r.sequence;
  }
  std::printf("loop: worst error %.3f mm over 0-36.5 mm (bound 0.5 mm)\n", worst_mm);
  RecordProperty("loop_worst_error_um", static_cast<int>(worst_mm * 1000));
  EXPECT_LE(worst_mm, 0.5);
}

TEST(Emulator, SheathFollowsThePotentiometerWithinOneMillimetre) {
  Emulator emulator(options(6));
  const double sweep_us = 4e6;  // 0 -> 230 mm in 4 s, 2 mV RMS noise
  auto insertion_mm = [&](uint64_t t) { return std::min(230.0, 230.0 * static_cast<double>(t) / sweep_us); };
  emulator.set_motion([&](uint64_t t) { return MotionState{.insertion_mm = insertion_mm(t), .loop_mm = 10.0}; });
  const auto reports = run_for(emulator, 4'000'000);
  double worst_mm = 0.0;
  for (const auto& r : reports) {
    const double truth = mean_over_adc_samples(r.sequence, insertion_mm);
    worst_mm = std::max(worst_mm, std::abs(r.sheath_um * 1e-3 - truth));
  }
  std::printf("sheath: worst error %.3f mm over 0-230 mm (bound 1.0 mm)\n", worst_mm);
  RecordProperty("sheath_worst_error_um", static_cast<int>(worst_mm * 1000));
  EXPECT_LE(worst_mm, 1.0);
}

TEST(Emulator, ReadingsOutsideTheCalibratedRangeAreClampedAndFlagged) {
  Emulator emulator;
  emulator.set_motion([](uint64_t t) {
    return t < 100'000 ? MotionState{.insertion_mm = -8.0, .loop_mm = 39.0}
                       : MotionState{.insertion_mm = 240.0, .loop_mm = -2.0, .cut = true};
  });
  const auto reports = run_for(emulator, 200'000);
  ASSERT_EQ(reports.size(), 200u);
  const auto& low = reports[50];
  EXPECT_EQ(low.sheath_um, 0);
  EXPECT_EQ(low.loop_um, 36500);
  EXPECT_NE(low.status & LP3500_STATUS_SHEATH_CLAMPED, 0);
  EXPECT_NE(low.status & LP3500_STATUS_LOOP_CLAMPED, 0);
  EXPECT_EQ(low.pedals, 0);
  const auto& high = reports[150];
  EXPECT_EQ(high.sheath_um, 230000);
  EXPECT_EQ(high.loop_um, 0);
  EXPECT_NE(high.status & LP3500_STATUS_SHEATH_CLAMPED, 0);
  EXPECT_NE(high.status & LP3500_STATUS_LOOP_CLAMPED, 0);
  EXPECT_EQ(high.pedals, LP3500_PEDAL_CUT);
  EXPECT_NE(high.status & LP3500_STATUS_DEFAULT_CALIBRATION, 0);
}

/// All three axes at 90 % of the maximum count rate (18 000 counts/s), plus moving sensors.
MotionState fast_motion(uint64_t t_us) {
  const double counts_per_s = 0.9 * LP3500_MAX_COUNT_RATE_HZ;
  const double rad_per_us = counts_per_s / 4096.0 * 2.0 * std::numbers::pi * 1e-6;
  const double t = static_cast<double>(t_us);
  return MotionState{.yaw_rad = rad_per_us * t, .pitch_rad = -rad_per_us * t,
                     .roll_rad = 0.3 * std::sin(t * 1e-5),  // reversals
                     .insertion_mm = 50.0 + 40.0 * std::sin(t * 2e-6), .loop_mm = 18.0 + 15.0 * std::sin(t * 3e-6),
                     .cut = (t_us / 37'000) % 2 == 1};
}

std::vector<lp3500_input_report> run_fast(uint64_t stall_at_us, uint64_t stall_us, uint64_t total_us) {
  Emulator emulator(options(9));
  emulator.set_motion(fast_motion);
  emulator.advance(stall_at_us);
  emulator.stall_main_loop(stall_us);
  std::vector<lp3500_input_report> reports = drain(emulator);
  for (const auto& r : run_for(emulator, total_us - stall_at_us)) reports.push_back(r);
  return reports;
}

TEST(Emulator, ReportsSurviveADocumentedStallOfTheMainLoopWithoutLoss) {
  const uint64_t stall_us = LP3500_MAX_STALL_MS * 1000;
  const auto stalled = run_fast(50'000, stall_us, 400'000);
  const auto smooth = run_fast(50'000, 0, 400'000);
  ASSERT_EQ(stalled.size(), 400u);
  ASSERT_EQ(smooth.size(), stalled.size());
  int late = 0;
  for (size_t i = 0; i < stalled.size(); ++i) {
    lp3500_input_report a = stalled[i], b = smooth[i];
    EXPECT_EQ(a.sequence, i);
    EXPECT_EQ(a.status & LP3500_STATUS_OVERRUN, 0) << "report " << i;
    EXPECT_EQ(a.adc_samples, static_cast<uint16_t>(4 * (i + 1)));
    if (a.status & LP3500_STATUS_STALL) ++late;
    a.status &= static_cast<uint16_t>(~LP3500_STATUS_STALL);
    EXPECT_GE(a.ring_high_water, b.ring_high_water);
    a.ring_high_water = b.ring_high_water;
    // Identical to the unstalled run in every field but the STALL flag and the ring's peak.
    uint8_t packed_a[LP3500_INPUT_REPORT_SIZE], packed_b[LP3500_INPUT_REPORT_SIZE];
    lp3500_pack_input_report(&a, packed_a);
    lp3500_pack_input_report(&b, packed_b);
    EXPECT_EQ(std::memcmp(packed_a, packed_b, sizeof packed_a), 0) << "report " << i;
    // Counts equal the true counts at the period's last capture.
    const uint64_t last_us = ((uint64_t{a.sequence} + 1) * LP3500_REPORT_TICKS - 1) * LP3500_TICK_US;
    const MotionState m = fast_motion(last_us);
    SensorModel s;
    EXPECT_EQ(a.encoder_counts[0], s.encoder_count(m.yaw_rad) - s.encoder_count(0.0)) << "report " << i;
    EXPECT_EQ(a.encoder_counts[1], s.encoder_count(m.pitch_rad) - s.encoder_count(0.0)) << "report " << i;
    EXPECT_EQ(a.encoder_counts[2], s.encoder_count(m.roll_rad) - s.encoder_count(0.0)) << "report " << i;
    EXPECT_EQ(a.illegal_transitions[0] + a.illegal_transitions[1] + a.illegal_transitions[2], 0);
  }
  EXPECT_GE(late, 95);  // the periods closed during the stall went out late, flagged
  std::printf("stall of %llu ms: %d reports late, none lost; edge ring peak %u of %u\n",
              static_cast<unsigned long long>(LP3500_MAX_STALL_MS), late, stalled.back().ring_high_water,
              LP3500_EDGE_RING_CAPACITY);
}

TEST(Emulator, AStallBeyondTheRingsRaisesTheOverrunFlag) {
  const auto reports = run_fast(50'000, 400'000, 600'000);
  bool overrun = false;
  for (const auto& r : reports) overrun = overrun || (r.status & LP3500_STATUS_OVERRUN);
  EXPECT_TRUE(overrun);
}

TEST(Emulator, FeatureReportsReadIdentityAndWriteOnlyValidCalibrations) {
  EmulatorOptions with_serial;
  with_serial.serial_number = 4242;
  Emulator emulator(with_serial);
  lp3500_identity id{};
  const auto identity_bytes = emulator.get_feature_report(LP3500_REPORT_ID_IDENTITY);
  ASSERT_EQ(lp3500_unpack_identity(identity_bytes.data(), identity_bytes.size(), &id), LP3500_OK);
  EXPECT_EQ(id.serial_number, 4242u);
  EXPECT_EQ(id.report_rate_hz, 1000);
  EXPECT_EQ(id.max_stall_ms, LP3500_MAX_STALL_MS);
  EXPECT_EQ(id.calibration_written, 0);
  EXPECT_STREQ(id.name, "Resecto LP3500");

  lp3500_calibration written = lp3500_default_calibration;
  written.sheath_offset_um += 1000;
  for (auto& h : written.hall_sum) h = static_cast<uint16_t>(h + 3);
  std::vector<uint8_t> bytes(LP3500_CALIBRATION_REPORT_SIZE);
  lp3500_pack_calibration(&written, 0, bytes.data());
  ASSERT_EQ(emulator.set_feature_report(bytes.data(), bytes.size()), LP3500_OK);

  // A corrupted write and a non-monotone one are refused; the good calibration stays.
  auto corrupted = bytes;
  corrupted[100] ^= 1;
  EXPECT_EQ(emulator.set_feature_report(corrupted.data(), corrupted.size()), LP3500_ERROR_CRC);
  lp3500_calibration folded = written;
  std::swap(folded.hall_sum[10], folded.hall_sum[11]);
  lp3500_pack_calibration(&folded, 0, bytes.data());
  EXPECT_EQ(emulator.set_feature_report(bytes.data(), bytes.size()), LP3500_ERROR_NOT_MONOTONE);
  EXPECT_EQ(emulator.set_feature_report(identity_bytes.data(), identity_bytes.size()), LP3500_ERROR_REPORT_ID);

  const auto read = emulator.get_feature_report(LP3500_REPORT_ID_CALIBRATION);
  lp3500_calibration active{};
  uint8_t last = 0;
  ASSERT_EQ(lp3500_unpack_calibration(read.data(), read.size(), &active, &last), LP3500_OK);
  EXPECT_EQ(std::memcmp(&active, &written, sizeof active), 0);
  EXPECT_EQ(last, LP3500_ERROR_NOT_MONOTONE);  // the last write's verdict

  emulator.advance(5000);
  const auto reports = drain(emulator);
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back().status & LP3500_STATUS_DEFAULT_CALIBRATION, 0);
  EXPECT_TRUE(emulator.get_feature_report(0x7F).empty());
}

TEST(Emulator, SameSeedSameBytesOtherSeedOtherNoise) {
  auto run = [](uint64_t seed) {
    Emulator emulator(options(seed));
    emulator.set_motion(fast_motion);
    std::vector<uint8_t> all;
    for (int step = 0; step < 200; ++step) {
      emulator.advance(1000);
      while (auto bytes = emulator.read_input_report()) all.insert(all.end(), bytes->begin(), bytes->end());
    }
    return all;
  };
  const auto a = run(7), b = run(7), c = run(8);
  EXPECT_EQ(a.size(), 200u * LP3500_INPUT_REPORT_SIZE);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(Emulator, ReportsBoardRamAndTableSizes) {
  const size_t board = sizeof(lp3500_board);
  const size_t calibration = sizeof(lp3500_calibration);
  const size_t descriptor = sizeof lp3500_report_descriptor;
  std::printf("board RAM %zu bytes (edge ring %u entries, ADC ring %u, tx queue %u reports); "
              "calibration %zu bytes; Hall table %zu bytes; transition table 16 bytes; descriptor %zu bytes\n",
              board, LP3500_EDGE_RING_CAPACITY, LP3500_ADC_RING_CAPACITY, LP3500_TX_QUEUE_CAPACITY, calibration,
              sizeof lp3500_default_calibration.hall_sum + sizeof lp3500_default_calibration.loop_um, descriptor);
  RecordProperty("board_ram_bytes", static_cast<int>(board));
  RecordProperty("calibration_bytes", static_cast<int>(calibration));
  EXPECT_LT(board, 128u * 1024u);  // the LP3500 has 512 KiB of SRAM; we keep to a quarter
  EXPECT_EQ(sizeof lp3500_default_calibration.hall_sum, 148u);  // the paper's 148 values (as 74 pairs)
}

}  // namespace
