// The host calibration library: the file round-trips and its errors name the field; the fits recover
// a known line and the magnet model's table, refuse what cannot be monotone, and a table fitted from
// emulated caliper measurements, written to the board, reads the loop within 0.5 mm.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "device/calibration/calibration.h"
#include "device/calibration/calibration_fit.h"
#include "firmware/emulator/lp3500_emulator.h"
#include "resecto/lp3500_sensors.h"

namespace {

using namespace resecto::device;
using resecto::firmware::Emulator;
using resecto::firmware::MotionState;

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("resecto_calibration_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

TEST(Calibration, DefaultMatchesTheBoardAndRoundTripsThroughTheFile) {
  const Calibration c = default_calibration();
  EXPECT_NEAR(c.sheath_gain_mm_per_count, -0.221072, 1e-9);
  EXPECT_EQ(c.translation_mm[2], -150.0);
  const auto board = to_board(c);
  ASSERT_TRUE(board.ok()) << board.error();
  EXPECT_EQ(std::memcmp(&*board, &lp3500_default_calibration, sizeof(lp3500_calibration)), 0);

  Calibration changed = c;
  changed.encoder_counts_per_revolution = {2000, 4096, 10000};
  changed.rotation = {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};
  changed.translation_mm = {1.5, -2.25, -149.0};
  const auto path = scratch("round_trip.json");
  ASSERT_TRUE(write_calibration(changed, path).ok());
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp." + std::to_string(::getpid())));
  const auto read = read_calibration(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read->encoder_counts_per_revolution, changed.encoder_counts_per_revolution);
  EXPECT_EQ(read->rotation, changed.rotation);
  EXPECT_EQ(read->translation_mm, changed.translation_mm);
  EXPECT_EQ(read->hall_sum_counts, changed.hall_sum_counts);
  EXPECT_EQ(read->sheath_offset_mm, changed.sheath_offset_mm);
}

TEST(Calibration, ReaderErrorsNameTheFileAndField) {
  const std::string good = calibration_to_json(default_calibration());
  auto expect_error = [&](std::string text, const std::string& fragment) {
    const auto result = parse_calibration(text, "cal.json");
    ASSERT_FALSE(result.ok()) << "accepted: " << fragment;
    EXPECT_NE(result.error().find("cal.json"), std::string::npos) << result.error();
    EXPECT_NE(result.error().find(fragment), std::string::npos) << result.error();
  };
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  ASSERT_TRUE(parse_calibration(good, "cal.json").ok());
  expect_error("{", "not valid JSON");
  expect_error(replace("\"gain_mm_per_count\"", "\"gain\""), "sheath.gain_mm_per_count: missing");
  expect_error(replace("\"resecto-calibration\"", "\"other\""), "format");
  expect_error(replace("4096,", "-3,"), "encoders.counts_per_revolution[0]");
  // One count a turn would place the joint to 360 degrees (audit 29, F13: accepted, a 73 N peak).
  expect_error(replace("4096,", "1,"), "not a whole number in 100-1000000000");
  expect_error(replace("-150.0", "\"far\""), "registration.translation_mm[2]: not a number");
  // A non-monotone table: swap two Hall sums.
  expect_error(replace("3091,", "2900,"), "hall_table[2]");
  // A mirror is not a rotation.
  Calibration mirrored = default_calibration();
  mirrored.rotation[0][0] = -1.0;
  expect_error(calibration_to_json(mirrored), "registration.rotation");
  EXPECT_FALSE(read_calibration(scratch("absent.json")).ok());
}

// Audit 6, A: a misspelt key was ignored (the field it meant kept its value) and a repeated key read
// its last value; both are refused by path, as presets refuse unknown keys.
TEST(Calibration, ReaderRefusesUnknownAndRepeatedKeysByPath) {
  const std::string good = calibration_to_json(default_calibration());
  const auto error_of = [](const std::string& text) {
    const auto result = parse_calibration(text, "cal.json");
    return result.ok() ? std::string("accepted") : result.error();
  };
  std::string extra = good;
  extra.insert(extra.find("\"min_mm\""), "\"minimum_mm\": 0, ");
  EXPECT_EQ(error_of(extra), "cal.json: sheath.minimum_mm: unknown key (sheath holds gain_mm_per_count, offset_mm, min_mm, max_mm)");
  EXPECT_EQ(error_of("{\"comment\": \"x\", " + good.substr(1)),
            "cal.json: comment: unknown key (the file holds format, version, sheath, hall_table, encoders, registration)");
  std::string twice = good;
  twice.insert(twice.find("\"min_mm\""), "\"offset_mm\": -1000000, ");
  EXPECT_EQ(error_of(twice), "cal.json: sheath.offset_mm: the key appears twice in its object");
  EXPECT_EQ(error_of(good.substr(0, good.rfind('}')) + ", \"version\": 1}"), "cal.json: version: the key appears twice in its object");
}

// Audit 6, A: the emulated board encodes with the calibration it decodes with, so a nonsense sensor
// model ran unnoticed; one that maps the whole sensor range off the travel is refused, saying why.
TEST(Calibration, ReaderRefusesSensorModelsThatMapOffTheTravel) {
  const auto error_of = [](const Calibration& c) {
    const auto result = parse_calibration(calibration_to_json(c), "cal.json");
    return result.ok() ? std::string("accepted") : result.error();
  };
  Calibration far = default_calibration();
  far.sheath_offset_mm = -1e6;
  EXPECT_EQ(error_of(far),
            "cal.json: sheath: potentiometer counts 0-4095 map to -1000905.29 .. -1000000 mm, all outside the sheath's travel "
            "(min_mm 0 to max_mm 230): gain_mm_per_count or offset_mm is wrong");
  Calibration still = default_calibration();
  still.sheath_gain_mm_per_count = 0.0;
  EXPECT_EQ(
      error_of(still),
      "cal.json: sheath.gain_mm_per_count: 0 is zero to the board's 0.000001 mm per count, and a zero gain reads every count as offset_mm");
  Calibration swapped = default_calibration();
  swapped.sheath_min_mm = 230.0;
  swapped.sheath_max_mm = 0.0;
  EXPECT_EQ(error_of(swapped), "cal.json: sheath: min_mm 230 must be below max_mm 0");
  Calibration beyond = default_calibration();
  for (double& mm : beyond.loop_mm) mm += 20.0;
  EXPECT_EQ(error_of(beyond), "cal.json: hall_table.loop_mm[34]: 37 mm is outside the loop's 0-36.5 mm travel");

  // Partly on the travel is a real potentiometer's case (the default maps counts to -90 .. 815 mm), and
  // a steeper gain or a table over half the travel still describe some device.
  Calibration steeper = default_calibration();
  steeper.sheath_gain_mm_per_count = -0.25;
  EXPECT_EQ(error_of(steeper), "accepted");
  Calibration edge = default_calibration();
  edge.sheath_offset_mm = -kAdcMaxCounts * edge.sheath_gain_mm_per_count;  // count 4095 reads 0 mm, the travel's end
  EXPECT_EQ(error_of(edge), "accepted");
  Calibration half = default_calibration();
  for (double& mm : half.loop_mm) mm *= 0.5;
  EXPECT_EQ(error_of(half), "accepted");
}

TEST(CalibrationFit, SheathLeastSquaresRecoversTheLineAndReportsResiduals) {
  std::vector<SheathSample> samples;
  for (int i = 0; i <= 23; ++i) {
    const double position = 10.0 * i;
    const double counts = (position - 815.0) / -0.22 + (i % 2 ? 0.5 : -0.5);  // +-0.5 count alternation
    samples.push_back({position, counts, i + 2});
  }
  const auto fit = fit_sheath(samples, "sheath.csv");
  ASSERT_TRUE(fit.ok()) << fit.error();
  EXPECT_NEAR(fit->gain_mm_per_count, -0.22, 1e-4);
  EXPECT_NEAR(fit->offset_mm, 815.0, 0.2);
  EXPECT_EQ(fit->min_mm, 0.0);
  EXPECT_EQ(fit->max_mm, 230.0);
  EXPECT_EQ(fit->residuals.size(), 24u);
  EXPECT_GT(fit->max_abs_mm, 0.09);  // about half a count of 0.22 mm
  EXPECT_LT(fit->max_abs_mm, 0.13);
  // Normal equations of least squares: residuals sum to zero and are orthogonal to the readings.
  double sum = 0.0, moment = 0.0;
  for (size_t i = 0; i < samples.size(); ++i) {
    sum += fit->residuals[i].residual_mm;
    moment += fit->residuals[i].residual_mm * (samples[i].potentiometer_counts - 3000.0);
  }
  EXPECT_NEAR(sum, 0.0, 1e-9);
  EXPECT_NEAR(moment, 0.0, 1e-6);
  EXPECT_EQ(fit->residuals[3].line, 5);

  std::vector<SheathSample> flat = {{0.0, 3000.0, 2}, {10.0, 3000.0, 3}};
  const auto refused = fit_sheath(flat, "sheath.csv");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("same potentiometer reading"), std::string::npos);
}

TEST(CalibrationFit, HallTableRefusesNonMonotoneShortOrFlatData) {
  auto sweep = [](double from, double to, double slope) {
    std::vector<HallSample> s;
    int line = 2;
    for (double x = from; x <= to + 1e-9; x += 1.0) s.push_back({x, 3000.0 + slope * x, line++});
    return s;
  };
  ASSERT_TRUE(fit_hall_table(sweep(0, 36, 20.0), "h.csv").ok());
  auto bump = sweep(0, 36, 20.0);
  bump[10].hall_sum_counts = bump[8].hall_sum_counts;  // 10 mm reads below 9 mm
  const auto non_monotone = fit_hall_table(bump, "h.csv");
  ASSERT_FALSE(non_monotone.ok());
  EXPECT_NE(non_monotone.error().find("h.csv:12"), std::string::npos) << non_monotone.error();
  const auto short_range = fit_hall_table(sweep(5, 36, 20.0), "h.csv");
  ASSERT_FALSE(short_range.ok());
  EXPECT_NE(short_range.error().find("cover"), std::string::npos) << short_range.error();
  const auto flat = fit_hall_table(sweep(0, 36, 1.0), "h.csv");  // 0.5 count per 0.5 mm: rounds flat
  ASSERT_FALSE(flat.ok());
  EXPECT_NE(flat.error().find("too flat"), std::string::npos) << flat.error();
  // Repeats at one position that disagree by far more than the sensor's noise (audit 8, G16): refused,
  // naming a row; repeats that agree within a count are averaged as before.
  auto disagreeing = sweep(0, 36, 20.0);
  disagreeing.push_back({10.0, 3000.0 + 20.0 * 10.0 + 30.0, 100});  // reads 1.5 mm off
  const auto misread = fit_hall_table(disagreeing, "h.csv");
  ASSERT_FALSE(misread.ok());
  EXPECT_NE(misread.error().find("rows repeated at one position disagree"), std::string::npos) << misread.error();
  auto agreeing = sweep(0, 36, 20.0);
  agreeing.push_back({10.0, 3000.0 + 20.0 * 10.0 + 1.0, 100});
  EXPECT_TRUE(fit_hall_table(agreeing, "h.csv").ok());
}

// The laboratory procedure on the emulated device: park the loop at caliper positions, average the
// reported Hall codes, fit, write the table to the board, then sweep the loop and compare.
TEST(CalibrationFit, TableFittedFromEmulatedCaliperMeasurementsReadsWithinHalfAMillimetre) {
  resecto::firmware::EmulatorOptions options;
  options.seed = 31;
  options.sensors.hall_gap_mm = 7.4;         // this unit's magnets sit a little further away...
  options.sensors.magnet_remanence_mt = 1150;  // ...and are a little weaker than the reference
  Emulator emulator(options);
  double parked_mm = 0.0;
  emulator.set_motion([&](uint64_t) { return MotionState{.insertion_mm = 50.0, .loop_mm = parked_mm}; });
  std::vector<HallSample> samples;
  int line = 2;
  for (double x = 0.0; x <= 36.5 + 1e-9; x += 0.25) {
    parked_mm = x;
    emulator.advance(20'000);
    double sum = 0.0;
    int n = 0;
    while (auto bytes = emulator.read_input_report()) {
      lp3500_input_report r{};
      ASSERT_EQ(lp3500_unpack_input_report(bytes->data(), bytes->size(), &r), LP3500_OK);
      if (n++ >= 2) sum += r.adc_hall_a + r.adc_hall_b;  // skip reports still settling
    }
    samples.push_back({x, sum / (n - 2), line++});
  }
  const auto fit = fit_hall_table(samples, "emulated.csv");
  ASSERT_TRUE(fit.ok()) << fit.error();
  EXPECT_LT(fit->max_abs_mm, 0.25);

  Calibration c = default_calibration();
  c.hall_sum_counts = fit->hall_sum_counts;
  c.loop_mm = fit->loop_mm;
  const auto board = to_board(c);
  ASSERT_TRUE(board.ok()) << board.error();
  std::vector<uint8_t> bytes(LP3500_CALIBRATION_REPORT_SIZE);
  lp3500_pack_calibration(&*board, 0, bytes.data());
  ASSERT_EQ(emulator.set_feature_report(bytes.data(), bytes.size()), LP3500_OK);

  const uint64_t start = emulator.time_us();
  auto loop_mm = [&](uint64_t t) { return 36.0 * static_cast<double>(t - start) / 2e6; };
  emulator.set_motion([&](uint64_t t) { return MotionState{.insertion_mm = 50.0, .loop_mm = loop_mm(t)}; });
  double worst = 0.0;
  for (int step = 0; step < 200; ++step) {
    emulator.advance(10'000);
    while (auto report = emulator.read_input_report()) {
      lp3500_input_report r{};
      ASSERT_EQ(lp3500_unpack_input_report(report->data(), report->size(), &r), LP3500_OK);
      const uint64_t period_start = uint64_t{r.sequence} * 1000;
      if (period_start < start) continue;
      const double truth = loop_mm(period_start + 375);  // mean of the 4 ADC instants
      worst = std::max(worst, std::abs(r.loop_um * 1e-3 - truth));
    }
  }
  std::printf("fitted table on a non-reference unit: worst loop error %.3f mm\n", worst);
  EXPECT_LE(worst, 0.5);
}

}  // namespace
