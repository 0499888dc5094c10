/* The LP3500 board program: a capture interrupt that polls the encoder/pedal port and feeds a ring
 * of changes, an ADC interrupt that feeds a ring of samples, and a main loop that decodes both rings
 * into 1 kHz input reports. Because the interrupts only capture, a stalled main loop loses nothing
 * until a ring fills (LP3500_MAX_STALL_MS at the worst-case rates); the paper's one-program design did. */
#ifndef RESECTO_LP3500_BOARD_H
#define RESECTO_LP3500_BOARD_H

#include <stdint.h>

#include "resecto/lp3500_protocol.h"
#include "resecto/lp3500_quadrature.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Firmware identity. */
#define LP3500_FIRMWARE_MAJOR 1u
#define LP3500_FIRMWARE_MINOR 0u
#define LP3500_FIRMWARE_PATCH 0u

/** Timebase: the capture interrupt polls the port at 40 kHz (a 25 us tick). */
#define LP3500_TICK_US 25u
#define LP3500_POLL_RATE_HZ 40000u
/** The ADC interrupt samples the three channels every 10 ticks (4 kHz); reports close every 40 (1 kHz). */
#define LP3500_ADC_TICKS 10u
#define LP3500_REPORT_TICKS 40u
#define LP3500_ADC_RATE_HZ (LP3500_POLL_RATE_HZ / LP3500_ADC_TICKS)
#define LP3500_REPORT_RATE_HZ (LP3500_POLL_RATE_HZ / LP3500_REPORT_TICKS)

/** Highest count rate per encoder that decodes exactly: one A/B change per two polls. Edge spacing at
 * this rate is 50 us; capture stays exact while every spacing stays above one poll (25 us), i.e. with
 * up to +-50 % timing jitter. Faster trains put two changes in one poll: an illegal transition. */
#define LP3500_MAX_COUNT_RATE_HZ (LP3500_POLL_RATE_HZ / 2u)

/** Port bits: encoder e has A at bit 2e and B at bit 2e+1; pedals at bits 6 (cut) and 7 (coagulate). */
#define LP3500_PORT_PEDAL_SHIFT 6u

/** Ring capacities (powers of two). Worst case all three encoders at the maximum rate fill the edge
 * ring at 60 000 entries/s: 8192 entries last 136 ms; the ADC ring lasts 256 ms at 4 kHz; the
 * transmit queue holds 256 reports (256 ms at 1 kHz). */
#define LP3500_EDGE_RING_CAPACITY 8192u
#define LP3500_ADC_RING_CAPACITY 1024u
#define LP3500_TX_QUEUE_CAPACITY 256u
/** The documented guarantee: a main-loop stall up to this long loses no count and no sample. */
#define LP3500_MAX_STALL_MS 100u

/** Everything the board holds in RAM; statically allocated by its owner, no heap anywhere. */
typedef struct lp3500_board {
  /* Written by the interrupts (single producer each). */
  volatile uint32_t tick;                          /**< captures so far; stamps ring entries */
  uint8_t last_port;                               /**< port at the previous capture */
  volatile uint8_t overrun_pending;                /**< a ring was full: an entry was dropped */
  uint16_t edge_high_water;
  volatile uint16_t edge_head;
  volatile uint16_t adc_head;
  uint32_t edge_tick[LP3500_EDGE_RING_CAPACITY];
  uint8_t edge_port[LP3500_EDGE_RING_CAPACITY];
  uint32_t adc_tick[LP3500_ADC_RING_CAPACITY];
  uint16_t adc_code[LP3500_ADC_RING_CAPACITY][3];  /**< potentiometer, Hall A, Hall B */

  /* Owned by the main loop (single consumer). */
  volatile uint16_t edge_tail;
  volatile uint16_t adc_tail;
  lp3500_quadrature encoders[LP3500_ENCODER_COUNT];
  uint8_t pedals;
  uint32_t report_end_tick;                        /**< end of the period being accumulated */
  uint32_t sequence;
  uint64_t device_time_us;                         /**< end time of the period being accumulated */
  uint32_t period_code_sum[3];                     /**< sums of the period's ADC codes */
  uint16_t period_samples;
  uint16_t last_adc[3];                            /**< last reported means, repeated if a period is empty */
  uint16_t adc_samples;                            /**< ADC sample sets consumed since power-up, wraps */

  /* USB: reports waiting for the host, and the feature-report state. */
  uint8_t tx_queue[LP3500_TX_QUEUE_CAPACITY][LP3500_INPUT_REPORT_SIZE];
  uint16_t tx_head;
  uint16_t tx_tail;
  lp3500_calibration calibration;
  uint8_t calibration_written;
  uint8_t last_calibration_result;
  uint32_t serial_number;
} lp3500_board;

/** Power-up: default calibration, counts zero, decoders synchronised to `initial_port`. */
void lp3500_board_init(lp3500_board* board, uint32_t serial_number, uint8_t initial_port);

/** The 40 kHz capture interrupt: stamps and pushes `port` when it differs from the previous poll. */
void lp3500_capture_isr(lp3500_board* board, uint8_t port);

/** The ADC interrupt (every LP3500_ADC_TICKS ticks): pushes one 12-bit sample set stamped with the
 * current tick. */
void lp3500_adc_isr(lp3500_board* board, uint16_t potentiometer, uint16_t hall_a, uint16_t hall_b);

/** One pass of the main loop: decodes captured entries and packs every report period the interrupts
 * have completed. Returns how many reports it queued. */
unsigned lp3500_main_loop_step(lp3500_board* board);

/** The USB IN endpoint: copies out the oldest queued input report; 0 when none is waiting. */
int lp3500_take_input_report(lp3500_board* board, uint8_t out[LP3500_INPUT_REPORT_SIZE]);

/** GET_FEATURE: writes the report `report_id` into `out` (capacity `capacity`); returns its size or 0
 * for an unknown id or too small a buffer. */
unsigned lp3500_get_feature(const lp3500_board* board, uint8_t report_id, uint8_t* out, unsigned capacity);

/** SET_FEATURE: only the calibration report is writable. A bad frame or calibration is rejected and the
 * previous calibration kept; the result is also reported in byte 2 of the next calibration get. */
lp3500_result lp3500_set_feature(lp3500_board* board, const uint8_t* data, unsigned length);

/** The board's identity as the identity feature report states it. */
lp3500_identity lp3500_board_identity(const lp3500_board* board);

#ifdef __cplusplus
}
#endif

#endif /* RESECTO_LP3500_BOARD_H */
