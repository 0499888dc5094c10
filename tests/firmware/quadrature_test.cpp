// Generated quadrature pulse trains (forward, backward, reversals, timing jitter, up to and past the
// documented maximum rate) polled by the board's capture interrupt: decoded counts equal the true
// counts, and faster trains raise the illegal-transition flag instead of erring silently.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "firmware/emulator/sensor_model.h"
#include "resecto/lp3500_board.h"

namespace {

using resecto::firmware::NoiseSource;

/// One encoder's edges: times in microseconds (increasing) and directions (+1 / -1).
struct PulseTrain {
  std::vector<double> time_us;
  std::vector<int> direction;

  int32_t count_at(double t_us) const {
    const auto end = std::upper_bound(time_us.begin(), time_us.end(), t_us) - time_us.begin();
    int32_t count = 0;
    for (long i = 0; i < end; ++i) count += direction[i];
    return count;
  }
};

/// `edges` edges at `rate_hz` with spacing jitter +-`jitter` (fraction), reversing every `run` edges
/// (0: never), starting in direction `first`.
PulseTrain make_train(int edges, double rate_hz, double jitter, int run, int first, uint64_t seed) {
  NoiseSource noise(seed);
  PulseTrain train;
  double t = 100.0;
  int direction = first;
  for (int i = 0; i < edges; ++i) {
    if (run > 0 && i > 0 && i % run == 0) direction = -direction;
    t += 1e6 / rate_hz * (1.0 + jitter * (2.0 * noise.uniform() - 1.0));
    train.time_us.push_back(t);
    train.direction.push_back(direction);
  }
  return train;
}

struct Decoded {
  std::array<int32_t, 3> counts{};
  std::array<uint16_t, 3> illegal{};
  uint16_t status_or = 0;
  int reports = 0;
  bool all_reports_matched = true;
};

/// Polls the three trains at the capture rate through a real board, taking reports as a host would
/// and checking each one's counts against the trains' counts at the report's last capture.
Decoded decode(const std::array<PulseTrain, 3>& trains) {
  auto board = std::make_unique<lp3500_board>();
  lp3500_board_init(board.get(), 1, 0);
  double end_us = 0;
  for (const auto& t : trains) end_us = std::max(end_us, t.time_us.empty() ? 0.0 : t.time_us.back());
  const uint64_t ticks = static_cast<uint64_t>(end_us / LP3500_TICK_US) + 2 * LP3500_REPORT_TICKS;
  Decoded out;
  std::vector<std::array<int32_t, 3>> truth_at_tick;
  std::array<size_t, 3> next_edge{};
  std::array<int32_t, 3> truth{};
  uint8_t bytes[LP3500_INPUT_REPORT_SIZE];
  for (uint64_t tick = 0; tick < ticks; ++tick) {
    const double t_us = static_cast<double>(tick * LP3500_TICK_US);
    unsigned port = 0;
    for (unsigned e = 0; e < 3; ++e) {
      const PulseTrain& train = trains[e];
      while (next_edge[e] < train.time_us.size() && train.time_us[next_edge[e]] <= t_us) {
        truth[e] += train.direction[next_edge[e]++];
      }
      port |= unsigned{lp3500_quadrature_state_of_count(truth[e])} << (2 * e);
    }
    truth_at_tick.push_back(truth);
    lp3500_capture_isr(board.get(), static_cast<uint8_t>(port));
    lp3500_main_loop_step(board.get());
    while (lp3500_take_input_report(board.get(), bytes)) {
      lp3500_input_report r{};
      EXPECT_EQ(lp3500_unpack_input_report(bytes, sizeof bytes, &r), LP3500_OK);
      EXPECT_EQ(r.sequence, static_cast<uint32_t>(out.reports));
      const uint64_t last_tick = (uint64_t{r.sequence} + 1) * LP3500_REPORT_TICKS - 1;
      for (unsigned e = 0; e < 3; ++e) {
        if (r.encoder_counts[e] != truth_at_tick[last_tick][e]) out.all_reports_matched = false;
        out.counts[e] = r.encoder_counts[e];
        out.illegal[e] = r.illegal_transitions[e];
      }
      out.status_or |= r.status;
      ++out.reports;
    }
  }
  return out;
}

void expect_exact(const std::array<PulseTrain, 3>& trains) {
  const Decoded d = decode(trains);
  EXPECT_GT(d.reports, 0);
  EXPECT_TRUE(d.all_reports_matched);
  for (unsigned e = 0; e < 3; ++e) {
    EXPECT_EQ(d.counts[e], trains[e].count_at(1e18)) << "encoder " << e;
    EXPECT_EQ(d.illegal[e], 0) << "encoder " << e;
  }
  EXPECT_EQ(d.status_or & (LP3500_STATUS_ILLEGAL_ENCODER_0 | LP3500_STATUS_ILLEGAL_ENCODER_1 |
                           LP3500_STATUS_ILLEGAL_ENCODER_2 | LP3500_STATUS_OVERRUN), 0);
}

TEST(Quadrature, TransitionTableCountsEveryLegalStepAndFlagsDoubleSteps) {
  lp3500_quadrature q;
  lp3500_quadrature_reset(&q, 0);
  for (int32_t c = 1; c <= 9; ++c) lp3500_quadrature_step(&q, lp3500_quadrature_state_of_count(c));
  EXPECT_EQ(q.count, 9);
  for (int32_t c = 8; c >= -5; --c) lp3500_quadrature_step(&q, lp3500_quadrature_state_of_count(c));
  EXPECT_EQ(q.count, -5);
  EXPECT_EQ(q.illegal_transitions, 0);
  lp3500_quadrature_step(&q, lp3500_quadrature_state_of_count(-3));  // two steps at once
  EXPECT_EQ(q.count, -5);  // not applied
  EXPECT_EQ(q.illegal_transitions, 1);
  EXPECT_EQ(q.illegal_pending, 1);
}

TEST(Quadrature, ForwardBackwardAndReversingTrainsDecodeExactly) {
  expect_exact({make_train(3000, 5000, 0.0, 0, +1, 1), make_train(3000, 5000, 0.0, 0, -1, 2),
                make_train(4000, 8000, 0.0, 7, +1, 3)});
}

TEST(Quadrature, JitteredTrainsAtTheMaximumRateDecodeExactly) {
  // 20 000 counts/s with +-40 % spacing jitter on all three axes at once, many reversals.
  const double rate = LP3500_MAX_COUNT_RATE_HZ;
  expect_exact({make_train(20000, rate, 0.4, 0, +1, 11), make_train(20000, rate, 0.4, 0, -1, 12),
                make_train(20000, rate, 0.4, 3, +1, 13)});
  expect_exact({make_train(20000, rate, 0.4, 1, -1, 14), make_train(20000, rate, 0.4, 50, +1, 15),
                make_train(20000, rate, 0.4, 2, +1, 16)});
}

TEST(Quadrature, TrainsAboveTheMaximumRateRaiseTheIllegalFlag) {
  const Decoded d = decode({make_train(20000, 3.0 * LP3500_MAX_COUNT_RATE_HZ, 0.3, 0, +1, 21),
                            make_train(100, 1000, 0.0, 0, +1, 22), make_train(100, 1000, 0.0, 0, +1, 23)});
  EXPECT_GT(d.illegal[0], 0);
  EXPECT_NE(d.status_or & LP3500_STATUS_ILLEGAL_ENCODER_0, 0);
  EXPECT_EQ(d.illegal[1], 0);
  EXPECT_EQ(d.counts[1], 100);
  EXPECT_EQ(d.status_or & LP3500_STATUS_ILLEGAL_ENCODER_1, 0);
}

}  // namespace
