/* 4x quadrature decoding of one optical encoder (channels A and B) by a transition table: the board's
 * main loop feeds it every captured port state; a both-channels-change step is counted, not applied. */
#ifndef RESECTO_LP3500_QUADRATURE_H
#define RESECTO_LP3500_QUADRATURE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** One encoder's decoder state. `state` is bit 0 = channel A, bit 1 = channel B. */
typedef struct lp3500_quadrature {
  int32_t count;                /**< 4x count since reset: +1 per forward edge */
  uint16_t illegal_transitions; /**< both channels changed between two captures; wraps */
  uint8_t state;                /**< last A/B state seen */
  uint8_t illegal_pending;      /**< an illegal transition since the flag was last taken */
} lp3500_quadrature;

/** Starts decoding from the channels' present state with a zero count. */
void lp3500_quadrature_reset(lp3500_quadrature* q, uint8_t ab_state);

/** Applies the step from the previous to `ab_state` (bit 0 = A, bit 1 = B). Forward is the Gray
 * sequence 00 -> A -> AB -> B -> 00 (state 0, 1, 3, 2). */
void lp3500_quadrature_step(lp3500_quadrature* q, uint8_t ab_state);

/** The A/B state that forward count `count` produces (the inverse of decoding, for generators). */
uint8_t lp3500_quadrature_state_of_count(int32_t count);

#ifdef __cplusplus
}
#endif

#endif /* RESECTO_LP3500_QUADRATURE_H */
