/* The quadrature transition table: 16 entries indexed by (previous state, new state), one lookup per
 * captured edge, no branches on direction. */
#include "resecto/lp3500_quadrature.h"

/* Marks a step where A and B both changed: the direction is unknowable, so it is counted, not applied. */
#define ILLEGAL 2

/* Index: previous * 4 + next, states as bit 0 = A, bit 1 = B; forward order 0 -> 1 -> 3 -> 2 -> 0. */
static const int8_t kTransition[16] = {
    /* prev 0 */ 0, +1, -1, ILLEGAL,
    /* prev 1 */ -1, 0, ILLEGAL, +1,
    /* prev 2 */ +1, ILLEGAL, 0, -1,
    /* prev 3 */ ILLEGAL, -1, +1, 0,
};

static const uint8_t kGray[4] = {0u, 1u, 3u, 2u};

void lp3500_quadrature_reset(lp3500_quadrature* q, uint8_t ab_state) {
  q->count = 0;
  q->illegal_transitions = 0;
  q->state = (uint8_t)(ab_state & 3u);
  q->illegal_pending = 0;
}

void lp3500_quadrature_step(lp3500_quadrature* q, uint8_t ab_state) {
  const uint8_t next = (uint8_t)(ab_state & 3u);
  const int8_t delta = kTransition[(q->state << 2) | next];
  if (delta == ILLEGAL) {
    q->illegal_transitions = (uint16_t)(q->illegal_transitions + 1u);
    q->illegal_pending = 1;
  } else {
    q->count += delta;
  }
  q->state = next;  /* resynchronise on the new state either way */
}

uint8_t lp3500_quadrature_state_of_count(int32_t count) {
  return kGray[(uint32_t)count & 3u];
}
