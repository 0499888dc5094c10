/* Integer sensor models: the board has no FPU, so every per-sample conversion here is integer
 * arithmetic with explicit rounding. 64-bit intermediates are C99 and keep sums of several samples
 * exact; each product's bound is given where it is formed. */
#include "resecto/lp3500_sensors.h"

int64_t lp3500_divide_rounded(int64_t numerator, int64_t denominator) {
  return numerator >= 0 ? (numerator + denominator / 2) / denominator
                        : -((-numerator + denominator / 2) / denominator);
}

int32_t lp3500_sheath_um(const lp3500_calibration* c, uint32_t code_sum, uint16_t sample_count, uint8_t* clamped) {
  /* |gain| <= 500 000 nm/count, code_sum <= 65535 * 4095: the product stays below 2^47. */
  const int64_t nm = (int64_t)c->sheath_gain_nm_per_count * (int64_t)code_sum;
  /* Clamped in 64 bits: an extreme offset cannot wrap before the range check. */
  const int64_t um = lp3500_divide_rounded(nm, (int64_t)sample_count * 1000) + c->sheath_offset_um;
  *clamped = 0;
  if (um < c->sheath_min_um) {
    *clamped = 1;
    return c->sheath_min_um;
  }
  if (um > c->sheath_max_um) {
    *clamped = 1;
    return c->sheath_max_um;
  }
  return (int32_t)um;
}

int32_t lp3500_loop_um(const lp3500_calibration* c, uint32_t hall_sum_total, uint16_t sample_count,
                       uint8_t* clamped) {
  /* Work in "sum over samples" units so the averaging keeps its sub-code resolution. */
  const int64_t n = sample_count;
  const int64_t h = (int64_t)hall_sum_total;
  const int increasing = c->hall_sum[1] > c->hall_sum[0];
  const unsigned last = LP3500_HALL_TABLE_POINTS - 1u;
  /* Position along the table in the direction of increasing loop travel: f(i) = +-hall_sum[i] * n. */
  const int64_t sign = increasing ? 1 : -1;
  const int64_t x = sign * h;
  unsigned lo = 0, hi = last;
  *clamped = 0;
  if (x <= sign * (int64_t)c->hall_sum[0] * n) {
    *clamped = x < sign * (int64_t)c->hall_sum[0] * n;
    return c->loop_um[0];
  }
  if (x >= sign * (int64_t)c->hall_sum[last] * n) {
    *clamped = x > sign * (int64_t)c->hall_sum[last] * n;
    return c->loop_um[last];
  }
  /* Binary search (iterative, no recursion): f(lo) < x < f(hi), shrink to adjacent entries. */
  while (hi - lo > 1u) {
    const unsigned mid = (lo + hi) / 2u;
    if (sign * (int64_t)c->hall_sum[mid] * n <= x) lo = mid; else hi = mid;
  }
  {
    const int64_t x0 = sign * (int64_t)c->hall_sum[lo] * n;
    const int64_t x1 = sign * (int64_t)c->hall_sum[hi] * n;
    const int64_t y0 = c->loop_um[lo];
    const int64_t dy = (int64_t)c->loop_um[hi] - y0;
    /* dy < 2^16, x - x0 < 2^13 * 2^16: the product stays below 2^45. */
    return (int32_t)(y0 + lp3500_divide_rounded(dy * (x - x0), x1 - x0));
  }
}
