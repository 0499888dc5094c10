/* The board program: capture interrupts push stamped entries into single-producer/single-consumer
 * rings, the main loop drains them in stamp order and closes one report per 40-tick period. Report
 * contents depend only on the stamps, never on when the main loop happened to run, so a stalled loop
 * produces the same reports, later (flagged STALL), as long as no ring fills. */
#include "resecto/lp3500_board.h"

#include <string.h>

#include "resecto/lp3500_sensors.h"

#define EDGE_MASK (LP3500_EDGE_RING_CAPACITY - 1u)
#define ADC_MASK (LP3500_ADC_RING_CAPACITY - 1u)
#define TX_MASK (LP3500_TX_QUEUE_CAPACITY - 1u)

/* Tick stamps wrap (after ~30 h); comparisons go through the signed difference. */
static int tick_before(uint32_t a, uint32_t b) { return (int32_t)(a - b) < 0; }

void lp3500_board_init(lp3500_board* board, uint32_t serial_number, uint8_t initial_port) {
  unsigned e;
  memset(board, 0, sizeof *board);
  board->last_port = initial_port;
  for (e = 0; e < LP3500_ENCODER_COUNT; ++e) {
    lp3500_quadrature_reset(&board->encoders[e], (uint8_t)(initial_port >> (2u * e)));
  }
  board->pedals = (uint8_t)(initial_port >> LP3500_PORT_PEDAL_SHIFT);
  board->report_end_tick = LP3500_REPORT_TICKS;
  board->device_time_us = (uint64_t)LP3500_REPORT_TICKS * LP3500_TICK_US;
  board->calibration = lp3500_default_calibration;
  board->serial_number = serial_number;
}

void lp3500_capture_isr(lp3500_board* board, uint8_t port) {
  const uint32_t stamp = board->tick;
  board->tick = stamp + 1u;
  if (port == board->last_port) return;  /* only changes are stored: ring use follows the edge rate */
  {
    const uint16_t used = (uint16_t)(board->edge_head - board->edge_tail);
    if (used >= LP3500_EDGE_RING_CAPACITY) {
      board->overrun_pending = 1;  /* dropped; last_port keeps the old state so the next change shows */
      return;
    }
    board->edge_tick[board->edge_head & EDGE_MASK] = stamp;
    board->edge_port[board->edge_head & EDGE_MASK] = port;
    board->edge_head = (uint16_t)(board->edge_head + 1u);
    board->last_port = port;
    if (used + 1u > board->edge_high_water) board->edge_high_water = (uint16_t)(used + 1u);
  }
}

void lp3500_adc_isr(lp3500_board* board, uint16_t potentiometer, uint16_t hall_a, uint16_t hall_b) {
  const uint16_t used = (uint16_t)(board->adc_head - board->adc_tail);
  const unsigned slot = board->adc_head & ADC_MASK;
  if (used >= LP3500_ADC_RING_CAPACITY) {
    board->overrun_pending = 1;
    return;
  }
  board->adc_tick[slot] = board->tick;
  board->adc_code[slot][0] = (uint16_t)(potentiometer & 0x0FFFu);
  board->adc_code[slot][1] = (uint16_t)(hall_a & 0x0FFFu);
  board->adc_code[slot][2] = (uint16_t)(hall_b & 0x0FFFu);
  board->adc_head = (uint16_t)(board->adc_head + 1u);
}

/* Decodes every captured entry stamped before the current period's end, in stamp order. */
static void drain_rings(lp3500_board* board) {
  unsigned e;
  while (board->edge_tail != board->edge_head) {
    const unsigned slot = board->edge_tail & EDGE_MASK;
    const uint8_t port = board->edge_port[slot];
    if (!tick_before(board->edge_tick[slot], board->report_end_tick)) break;
    for (e = 0; e < LP3500_ENCODER_COUNT; ++e) {
      lp3500_quadrature_step(&board->encoders[e], (uint8_t)(port >> (2u * e)));
    }
    board->pedals = (uint8_t)(port >> LP3500_PORT_PEDAL_SHIFT);
    board->edge_tail = (uint16_t)(board->edge_tail + 1u);
  }
  while (board->adc_tail != board->adc_head) {
    const unsigned slot = board->adc_tail & ADC_MASK;
    if (!tick_before(board->adc_tick[slot], board->report_end_tick)) break;
    board->period_code_sum[0] += board->adc_code[slot][0];
    board->period_code_sum[1] += board->adc_code[slot][1];
    board->period_code_sum[2] += board->adc_code[slot][2];
    board->period_samples = (uint16_t)(board->period_samples + 1u);
    board->adc_samples = (uint16_t)(board->adc_samples + 1u);
    board->adc_tail = (uint16_t)(board->adc_tail + 1u);
  }
}

/* Closes the current period into an input report at the tail of the transmit queue. */
static void pack_report(lp3500_board* board, uint32_t now) {
  lp3500_input_report r;
  unsigned e, k;
  uint32_t sums[3];
  uint16_t samples = board->period_samples;
  uint8_t sheath_clamped = 0, loop_clamped = 0;
  memset(&r, 0, sizeof r);
  r.sequence = board->sequence;
  r.device_time_us = board->device_time_us;
  r.pedals = (uint8_t)(board->pedals & (LP3500_PEDAL_CUT | LP3500_PEDAL_COAGULATE));
  for (e = 0; e < LP3500_ENCODER_COUNT; ++e) {
    lp3500_quadrature* q = &board->encoders[e];
    r.encoder_counts[e] = q->count;
    r.illegal_transitions[e] = q->illegal_transitions;
    if (q->illegal_pending) r.status |= (uint16_t)(LP3500_STATUS_ILLEGAL_ENCODER_0 << e);
    q->illegal_pending = 0;
  }
  if (samples == 0) {  /* repeat the last means rather than invent a reading */
    for (k = 0; k < 3; ++k) sums[k] = board->last_adc[k];
    samples = 1;
    r.status |= LP3500_STATUS_NO_ADC_SAMPLE;
  } else {
    for (k = 0; k < 3; ++k) {
      sums[k] = board->period_code_sum[k];
      board->last_adc[k] = (uint16_t)lp3500_divide_rounded((int64_t)sums[k], samples);
    }
  }
  r.adc_potentiometer = board->last_adc[0];
  r.adc_hall_a = board->last_adc[1];
  r.adc_hall_b = board->last_adc[2];
  r.sheath_um = lp3500_sheath_um(&board->calibration, sums[0], samples, &sheath_clamped);
  r.loop_um = lp3500_loop_um(&board->calibration, sums[1] + sums[2], samples, &loop_clamped);
  if (sheath_clamped) r.status |= LP3500_STATUS_SHEATH_CLAMPED;
  if (loop_clamped) r.status |= LP3500_STATUS_LOOP_CLAMPED;
  if (!tick_before(now, board->report_end_tick + LP3500_REPORT_TICKS)) r.status |= LP3500_STATUS_STALL;
  /* On the board this read-and-clear runs with interrupts masked. */
  if (board->overrun_pending) {
    r.status |= LP3500_STATUS_OVERRUN;
    board->overrun_pending = 0;
  }
  if (!board->calibration_written) r.status |= LP3500_STATUS_DEFAULT_CALIBRATION;
  r.adc_samples = board->adc_samples;
  r.ring_high_water = board->edge_high_water;
  lp3500_pack_input_report(&r, board->tx_queue[board->tx_head & TX_MASK]);
  board->tx_head = (uint16_t)(board->tx_head + 1u);

  board->sequence += 1u;
  board->report_end_tick += LP3500_REPORT_TICKS;
  board->device_time_us += (uint64_t)LP3500_REPORT_TICKS * LP3500_TICK_US;
  board->period_code_sum[0] = board->period_code_sum[1] = board->period_code_sum[2] = 0;
  board->period_samples = 0;
}

unsigned lp3500_main_loop_step(lp3500_board* board) {
  unsigned packed = 0;
  for (;;) {
    /* On the 8-bit board this 32-bit read runs with interrupts masked. */
    const uint32_t now = board->tick;
    drain_rings(board);
    /* Every capture stamped before the period's end has run once `now` reaches it. */
    if (tick_before(now, board->report_end_tick)) break;
    /* A full transmit queue holds the period back: the rings absorb it (back-pressure, not loss). */
    if ((uint16_t)(board->tx_head - board->tx_tail) >= LP3500_TX_QUEUE_CAPACITY) break;
    pack_report(board, now);
    ++packed;
  }
  return packed;
}

int lp3500_take_input_report(lp3500_board* board, uint8_t out[LP3500_INPUT_REPORT_SIZE]) {
  if (board->tx_tail == board->tx_head) return 0;
  memcpy(out, board->tx_queue[board->tx_tail & TX_MASK], LP3500_INPUT_REPORT_SIZE);
  board->tx_tail = (uint16_t)(board->tx_tail + 1u);
  return 1;
}

static uint16_t calibration_crc(const lp3500_calibration* c) {
  uint8_t bytes[LP3500_CALIBRATION_REPORT_SIZE];
  lp3500_pack_calibration(c, 0, bytes);
  return lp3500_crc16(bytes + 3, LP3500_CALIBRATION_REPORT_SIZE - 5u);
}

lp3500_identity lp3500_board_identity(const lp3500_board* board) {
  static const char kName[] = "Resecto LP3500";
  lp3500_identity id;
  memset(&id, 0, sizeof id);
  id.firmware_major = LP3500_FIRMWARE_MAJOR;
  id.firmware_minor = LP3500_FIRMWARE_MINOR;
  id.firmware_patch = LP3500_FIRMWARE_PATCH;
  id.serial_number = board->serial_number;
  id.report_rate_hz = LP3500_REPORT_RATE_HZ;
  id.adc_rate_hz = LP3500_ADC_RATE_HZ;
  id.encoder_poll_rate_hz = LP3500_POLL_RATE_HZ;
  id.max_stall_ms = LP3500_MAX_STALL_MS;
  id.edge_ring_capacity = LP3500_EDGE_RING_CAPACITY;
  id.calibration_crc = calibration_crc(&board->calibration);
  id.calibration_written = board->calibration_written;
  memcpy(id.name, kName, sizeof kName);
  return id;
}

unsigned lp3500_get_feature(const lp3500_board* board, uint8_t report_id, uint8_t* out, unsigned capacity) {
  if (report_id == LP3500_REPORT_ID_IDENTITY && capacity >= LP3500_IDENTITY_REPORT_SIZE) {
    const lp3500_identity id = lp3500_board_identity(board);
    lp3500_pack_identity(&id, out);
    return LP3500_IDENTITY_REPORT_SIZE;
  }
  if (report_id == LP3500_REPORT_ID_CALIBRATION && capacity >= LP3500_CALIBRATION_REPORT_SIZE) {
    lp3500_pack_calibration(&board->calibration, board->last_calibration_result, out);
    return LP3500_CALIBRATION_REPORT_SIZE;
  }
  return 0;
}

lp3500_result lp3500_set_feature(lp3500_board* board, const uint8_t* data, unsigned length) {
  lp3500_calibration incoming;
  lp3500_result result;
  if (length == 0) return LP3500_ERROR_LENGTH;
  if (data[0] != LP3500_REPORT_ID_CALIBRATION) return LP3500_ERROR_REPORT_ID;  /* identity is read-only */
  result = lp3500_unpack_calibration(data, length, &incoming, NULL);
  if (result == LP3500_OK) {
    board->calibration = incoming;
    board->calibration_written = 1;
  }
  board->last_calibration_result = (uint8_t)result;
  return result;
}
