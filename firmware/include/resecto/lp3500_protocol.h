/* The LP3500 HID protocol, shared by the board firmware (C99) and the host (C++20): ids, report
 * layouts, explicit little-endian pack/unpack, CRC and the report descriptor, so the two cannot drift.
 * The byte-layout tables live in firmware/README.md; every offset below is the one written there. */
#ifndef RESECTO_LP3500_PROTOCOL_H
#define RESECTO_LP3500_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- identity ----------------------------------------------------------------------------- */

/** Default USB vendor id (pid.codes, the open-source hardware vendor id); overridable on the host. */
#define LP3500_VENDOR_ID 0x1209u
/** Default USB product id of the Resecto LP3500 interface. */
#define LP3500_PRODUCT_ID 0x3500u
/** Bumped whenever any layout below changes; every report carries it in byte 1. */
#define LP3500_PROTOCOL_VERSION 1u

/** Report ids (byte 0 of every report, as hidraw and hidapi deliver numbered reports). */
#define LP3500_REPORT_ID_INPUT 0x01u
#define LP3500_REPORT_ID_IDENTITY 0x02u
#define LP3500_REPORT_ID_CALIBRATION 0x03u

/** Sizes in bytes including the report id byte. */
#define LP3500_INPUT_REPORT_SIZE 64u
#define LP3500_IDENTITY_REPORT_SIZE 64u
#define LP3500_CALIBRATION_REPORT_SIZE 318u

/** Number of encoder axes (yaw, pitch, roll in that order) and of Hall table points. */
#define LP3500_ENCODER_COUNT 3u
#define LP3500_HALL_TABLE_POINTS 74u
/** Spacing of the Hall table in loop travel: 0.5 mm (the paper's 148 values = 74 pairs). */
#define LP3500_HALL_TABLE_STEP_UM 500u
/** Length of the identity name field, NUL padded. */
#define LP3500_NAME_LENGTH 32u

/* ---- input report bits -------------------------------------------------------------------- */

/** Pedal bits (input report byte 40). */
#define LP3500_PEDAL_CUT 0x01u
#define LP3500_PEDAL_COAGULATE 0x02u

/** Status flags (input report bytes 42-43). Flags describe this report's period only. */
#define LP3500_STATUS_ILLEGAL_ENCODER_0 0x0001u /**< yaw saw a both-channels-change transition */
#define LP3500_STATUS_ILLEGAL_ENCODER_1 0x0002u /**< pitch, likewise */
#define LP3500_STATUS_ILLEGAL_ENCODER_2 0x0004u /**< roll, likewise */
#define LP3500_STATUS_SHEATH_CLAMPED 0x0008u    /**< sheath reading outside the calibrated range */
#define LP3500_STATUS_LOOP_CLAMPED 0x0010u      /**< Hall sum outside the table */
#define LP3500_STATUS_STALL 0x0020u             /**< packed late: the main loop stalled (no data lost) */
#define LP3500_STATUS_OVERRUN 0x0040u           /**< a capture ring overflowed: data WAS lost */
#define LP3500_STATUS_DEFAULT_CALIBRATION 0x0080u /**< the board runs on its compiled-in calibration */
#define LP3500_STATUS_NO_ADC_SAMPLE 0x0100u     /**< no ADC sample fell in this period */

/* ---- results ------------------------------------------------------------------------------ */

/** Outcome of unpacking or validating a report; LP3500_OK is zero. */
typedef enum lp3500_result {
  LP3500_OK = 0,
  LP3500_ERROR_LENGTH = 1,         /**< buffer shorter/longer than the report */
  LP3500_ERROR_REPORT_ID = 2,      /**< byte 0 is not the expected report id */
  LP3500_ERROR_VERSION = 3,        /**< byte 1 is not LP3500_PROTOCOL_VERSION */
  LP3500_ERROR_CRC = 4,            /**< the trailing CRC does not match */
  LP3500_ERROR_POINT_COUNT = 5,    /**< calibration point count is not LP3500_HALL_TABLE_POINTS */
  LP3500_ERROR_NOT_MONOTONE = 6,   /**< Hall sums or loop positions not strictly monotone */
  LP3500_ERROR_SHEATH_RANGE = 7    /**< sheath gain zero/too large, or min >= max */
} lp3500_result;

/** A short constant description of `result`, for logs and error messages. */
static inline const char* lp3500_result_name(lp3500_result result) {
  switch (result) {
    case LP3500_OK: return "ok";
    case LP3500_ERROR_LENGTH: return "wrong report length";
    case LP3500_ERROR_REPORT_ID: return "wrong report id";
    case LP3500_ERROR_VERSION: return "wrong protocol version";
    case LP3500_ERROR_CRC: return "CRC mismatch";
    case LP3500_ERROR_POINT_COUNT: return "wrong Hall table point count";
    case LP3500_ERROR_NOT_MONOTONE: return "Hall table not strictly monotone";
    case LP3500_ERROR_SHEATH_RANGE: return "sheath gain or range out of bounds";
  }
  return "unknown error";
}

/* ---- decoded reports ---------------------------------------------------------------------- */

/** The 64-byte input report, decoded. Sent at 1 kHz; one per report period, none skipped. */
typedef struct lp3500_input_report {
  uint32_t sequence;                                /**< +1 per report, wraps */
  uint64_t device_time_us;                          /**< end of this report's period, board clock */
  int32_t encoder_counts[LP3500_ENCODER_COUNT];     /**< 4x quadrature counts since power-up */
  int32_t sheath_um;                                /**< sheath insertion, micrometres (clamped) */
  int32_t loop_um;                                  /**< loop travel, micrometres (clamped) */
  uint16_t adc_potentiometer;                       /**< 12-bit, mean over the period */
  uint16_t adc_hall_a;                              /**< 12-bit, mean over the period */
  uint16_t adc_hall_b;                              /**< 12-bit, mean over the period */
  uint8_t pedals;                                   /**< LP3500_PEDAL_* bits */
  uint16_t status;                                  /**< LP3500_STATUS_* bits */
  uint16_t illegal_transitions[LP3500_ENCODER_COUNT]; /**< cumulative per encoder, wraps */
  uint16_t adc_samples;                             /**< ADC samples since power-up, wraps */
  uint16_t ring_high_water;                         /**< peak edge-ring occupancy since power-up */
} lp3500_input_report;

/** The identity feature report (get only), decoded. */
typedef struct lp3500_identity {
  uint8_t firmware_major;
  uint8_t firmware_minor;
  uint8_t firmware_patch;
  uint32_t serial_number;
  uint16_t report_rate_hz;          /**< input reports per second (1000) */
  uint16_t adc_rate_hz;             /**< ADC sample sets per second */
  uint32_t encoder_poll_rate_hz;    /**< encoder port sampling rate of the capture interrupt */
  uint16_t max_stall_ms;            /**< longest main-loop stall guaranteed to lose nothing */
  uint16_t edge_ring_capacity;      /**< entries in the encoder edge ring */
  uint16_t calibration_crc;         /**< CRC of the active calibration report */
  uint8_t calibration_written;      /**< 0: compiled-in default, 1: written by the host */
  char name[LP3500_NAME_LENGTH];    /**< NUL padded */
} lp3500_identity;

/** The board's calibration: sheath linear model and the loop's Hall table (feature report 3). */
typedef struct lp3500_calibration {
  int32_t sheath_gain_nm_per_count; /**< sheath_um = gain * adc / 1000 + offset */
  int32_t sheath_offset_um;
  int32_t sheath_min_um;            /**< calibrated range; readings outside are clamped, flagged */
  int32_t sheath_max_um;
  uint16_t hall_sum[LP3500_HALL_TABLE_POINTS]; /**< adc_hall_a + adc_hall_b at each point */
  uint16_t loop_um[LP3500_HALL_TABLE_POINTS];  /**< loop travel at each point, strictly increasing */
} lp3500_calibration;

/** Largest accepted |sheath gain|: keeps gain * 4095 inside int32 on the board. */
#define LP3500_SHEATH_GAIN_LIMIT_NM 500000

/* ---- byte order and CRC ------------------------------------------------------------------- */

static inline void lp3500_put_u16(uint8_t* p, uint16_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}
static inline void lp3500_put_u32(uint8_t* p, uint32_t v) {
  lp3500_put_u16(p, (uint16_t)(v & 0xFFFFu));
  lp3500_put_u16(p + 2, (uint16_t)(v >> 16));
}
static inline void lp3500_put_u64(uint8_t* p, uint64_t v) {
  lp3500_put_u32(p, (uint32_t)(v & 0xFFFFFFFFu));
  lp3500_put_u32(p + 4, (uint32_t)(v >> 32));
}
static inline uint16_t lp3500_get_u16(const uint8_t* p) {
  return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
}
static inline uint32_t lp3500_get_u32(const uint8_t* p) {
  return (uint32_t)lp3500_get_u16(p) | ((uint32_t)lp3500_get_u16(p + 2) << 16);
}
static inline uint64_t lp3500_get_u64(const uint8_t* p) {
  return (uint64_t)lp3500_get_u32(p) | ((uint64_t)lp3500_get_u32(p + 4) << 32);
}
/* Signed values travel as two's complement; the casts below are defined conversions both ways
 * on every two's-complement target (all the board and host compilers we build with). */
static inline void lp3500_put_i32(uint8_t* p, int32_t v) { lp3500_put_u32(p, (uint32_t)v); }
static inline int32_t lp3500_get_i32(const uint8_t* p) {
  const uint32_t u = lp3500_get_u32(p);
  return u <= 0x7FFFFFFFu ? (int32_t)u : (int32_t)(u - 0x80000000u) - (int32_t)0x7FFFFFFF - 1;
}

/** CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final xor; "123456789" -> 0x29B1).
 * Bitwise rather than by table: 256 words of table cost more RAM than the board saves in time. */
static inline uint16_t lp3500_crc16(const uint8_t* data, size_t length) {
  uint16_t crc = 0xFFFFu;
  size_t i;
  for (i = 0; i < length; ++i) {
    int bit;
    crc = (uint16_t)(crc ^ (uint16_t)((uint16_t)data[i] << 8));
    for (bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x8000u) ? (uint16_t)((uint16_t)(crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
    }
  }
  return crc;
}

/** Checks length, id, version and the trailing CRC (over every byte before it). */
static inline lp3500_result lp3500_check_frame(const uint8_t* bytes, size_t length, size_t expected_length,
                                               uint8_t report_id) {
  if (length != expected_length) return LP3500_ERROR_LENGTH;
  if (bytes[0] != report_id) return LP3500_ERROR_REPORT_ID;
  if (bytes[1] != LP3500_PROTOCOL_VERSION) return LP3500_ERROR_VERSION;
  if (lp3500_get_u16(bytes + expected_length - 2) != lp3500_crc16(bytes, expected_length - 2)) {
    return LP3500_ERROR_CRC;
  }
  return LP3500_OK;
}

/** Writes id, version, and the CRC over bytes [0, size-2) into its last two bytes. */
static inline void lp3500_seal_frame(uint8_t* bytes, size_t size, uint8_t report_id) {
  bytes[0] = report_id;
  bytes[1] = (uint8_t)LP3500_PROTOCOL_VERSION;
  lp3500_put_u16(bytes + size - 2, lp3500_crc16(bytes, size - 2));
}

/* ---- input report ------------------------------------------------------------------------- */

/** Packs `r` into exactly LP3500_INPUT_REPORT_SIZE bytes (reserved bytes zero, CRC last). */
static inline void lp3500_pack_input_report(const lp3500_input_report* r, uint8_t out[LP3500_INPUT_REPORT_SIZE]) {
  unsigned i;
  memset(out, 0, LP3500_INPUT_REPORT_SIZE);
  lp3500_put_u32(out + 2, r->sequence);
  lp3500_put_u64(out + 6, r->device_time_us);
  for (i = 0; i < LP3500_ENCODER_COUNT; ++i) lp3500_put_i32(out + 14 + 4 * i, r->encoder_counts[i]);
  lp3500_put_i32(out + 26, r->sheath_um);
  lp3500_put_i32(out + 30, r->loop_um);
  lp3500_put_u16(out + 34, r->adc_potentiometer);
  lp3500_put_u16(out + 36, r->adc_hall_a);
  lp3500_put_u16(out + 38, r->adc_hall_b);
  out[40] = r->pedals;
  lp3500_put_u16(out + 42, r->status);
  for (i = 0; i < LP3500_ENCODER_COUNT; ++i) lp3500_put_u16(out + 44 + 2 * i, r->illegal_transitions[i]);
  lp3500_put_u16(out + 50, r->adc_samples);
  lp3500_put_u16(out + 52, r->ring_high_water);
  lp3500_seal_frame(out, LP3500_INPUT_REPORT_SIZE, (uint8_t)LP3500_REPORT_ID_INPUT);
}

/** Validates (length, id, version, CRC) and decodes; `r` is written only on LP3500_OK. */
static inline lp3500_result lp3500_unpack_input_report(const uint8_t* bytes, size_t length, lp3500_input_report* r) {
  unsigned i;
  const lp3500_result check =
      lp3500_check_frame(bytes, length, LP3500_INPUT_REPORT_SIZE, (uint8_t)LP3500_REPORT_ID_INPUT);
  if (check != LP3500_OK) return check;
  r->sequence = lp3500_get_u32(bytes + 2);
  r->device_time_us = lp3500_get_u64(bytes + 6);
  for (i = 0; i < LP3500_ENCODER_COUNT; ++i) r->encoder_counts[i] = lp3500_get_i32(bytes + 14 + 4 * i);
  r->sheath_um = lp3500_get_i32(bytes + 26);
  r->loop_um = lp3500_get_i32(bytes + 30);
  r->adc_potentiometer = lp3500_get_u16(bytes + 34);
  r->adc_hall_a = lp3500_get_u16(bytes + 36);
  r->adc_hall_b = lp3500_get_u16(bytes + 38);
  r->pedals = bytes[40];
  r->status = lp3500_get_u16(bytes + 42);
  for (i = 0; i < LP3500_ENCODER_COUNT; ++i) r->illegal_transitions[i] = lp3500_get_u16(bytes + 44 + 2 * i);
  r->adc_samples = lp3500_get_u16(bytes + 50);
  r->ring_high_water = lp3500_get_u16(bytes + 52);
  return LP3500_OK;
}

/* ---- identity feature report -------------------------------------------------------------- */

/** Packs the identity feature report (get only). */
static inline void lp3500_pack_identity(const lp3500_identity* id, uint8_t out[LP3500_IDENTITY_REPORT_SIZE]) {
  memset(out, 0, LP3500_IDENTITY_REPORT_SIZE);
  out[2] = id->firmware_major;
  out[3] = id->firmware_minor;
  out[4] = id->firmware_patch;
  lp3500_put_u32(out + 6, id->serial_number);
  lp3500_put_u16(out + 10, id->report_rate_hz);
  lp3500_put_u16(out + 12, id->adc_rate_hz);
  lp3500_put_u32(out + 14, id->encoder_poll_rate_hz);
  lp3500_put_u16(out + 18, id->max_stall_ms);
  lp3500_put_u16(out + 20, id->edge_ring_capacity);
  lp3500_put_u16(out + 22, id->calibration_crc);
  out[24] = id->calibration_written;
  memcpy(out + 26, id->name, LP3500_NAME_LENGTH);
  lp3500_seal_frame(out, LP3500_IDENTITY_REPORT_SIZE, (uint8_t)LP3500_REPORT_ID_IDENTITY);
}

/** Validates and decodes the identity feature report; `id` is written only on LP3500_OK. */
static inline lp3500_result lp3500_unpack_identity(const uint8_t* bytes, size_t length, lp3500_identity* id) {
  const lp3500_result check =
      lp3500_check_frame(bytes, length, LP3500_IDENTITY_REPORT_SIZE, (uint8_t)LP3500_REPORT_ID_IDENTITY);
  if (check != LP3500_OK) return check;
  id->firmware_major = bytes[2];
  id->firmware_minor = bytes[3];
  id->firmware_patch = bytes[4];
  id->serial_number = lp3500_get_u32(bytes + 6);
  id->report_rate_hz = lp3500_get_u16(bytes + 10);
  id->adc_rate_hz = lp3500_get_u16(bytes + 12);
  id->encoder_poll_rate_hz = lp3500_get_u32(bytes + 14);
  id->max_stall_ms = lp3500_get_u16(bytes + 18);
  id->edge_ring_capacity = lp3500_get_u16(bytes + 20);
  id->calibration_crc = lp3500_get_u16(bytes + 22);
  id->calibration_written = bytes[24];
  memcpy(id->name, bytes + 26, LP3500_NAME_LENGTH);
  id->name[LP3500_NAME_LENGTH - 1] = '\0';
  return LP3500_OK;
}

/* ---- calibration feature report ----------------------------------------------------------- */

/** Checks what the board requires of a calibration: point count is fixed by the type; loop positions
 * strictly increasing, Hall sums strictly monotone (either direction), sheath gain non-zero and
 * within LP3500_SHEATH_GAIN_LIMIT_NM, sheath_min_um < sheath_max_um. Returns the first violation;
 * `bad_index` (may be NULL) receives the table index at fault, or -1. */
static inline lp3500_result lp3500_validate_calibration(const lp3500_calibration* c, int* bad_index) {
  unsigned i;
  int direction;
  if (bad_index) *bad_index = -1;
  if (c->sheath_gain_nm_per_count == 0 || c->sheath_gain_nm_per_count > LP3500_SHEATH_GAIN_LIMIT_NM ||
      c->sheath_gain_nm_per_count < -LP3500_SHEATH_GAIN_LIMIT_NM || c->sheath_min_um >= c->sheath_max_um) {
    return LP3500_ERROR_SHEATH_RANGE;
  }
  direction = c->hall_sum[1] > c->hall_sum[0] ? 1 : -1;
  for (i = 1; i < LP3500_HALL_TABLE_POINTS; ++i) {
    const int step_ok = direction > 0 ? c->hall_sum[i] > c->hall_sum[i - 1] : c->hall_sum[i] < c->hall_sum[i - 1];
    if (!step_ok || c->loop_um[i] <= c->loop_um[i - 1]) {
      if (bad_index) *bad_index = (int)i;
      return LP3500_ERROR_NOT_MONOTONE;
    }
  }
  return LP3500_OK;
}

/** Packs the calibration feature report. `last_write_status` goes to byte 2 (the board reports the
 * lp3500_result of the last write there; a host writing sends 0). Byte 3 is the point count. */
static inline void lp3500_pack_calibration(const lp3500_calibration* c, uint8_t last_write_status,
                                           uint8_t out[LP3500_CALIBRATION_REPORT_SIZE]) {
  unsigned i;
  memset(out, 0, LP3500_CALIBRATION_REPORT_SIZE);
  out[2] = last_write_status;
  out[3] = (uint8_t)LP3500_HALL_TABLE_POINTS;
  lp3500_put_i32(out + 4, c->sheath_gain_nm_per_count);
  lp3500_put_i32(out + 8, c->sheath_offset_um);
  lp3500_put_i32(out + 12, c->sheath_min_um);
  lp3500_put_i32(out + 16, c->sheath_max_um);
  for (i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    lp3500_put_u16(out + 20 + 4 * i, c->hall_sum[i]);
    lp3500_put_u16(out + 22 + 4 * i, c->loop_um[i]);
  }
  lp3500_seal_frame(out, LP3500_CALIBRATION_REPORT_SIZE, (uint8_t)LP3500_REPORT_ID_CALIBRATION);
}

/** Validates framing, point count and the calibration itself, then decodes; `c` is written only on
 * LP3500_OK. `last_write_status` (may be NULL) receives byte 2. */
static inline lp3500_result lp3500_unpack_calibration(const uint8_t* bytes, size_t length, lp3500_calibration* c,
                                                      uint8_t* last_write_status) {
  lp3500_calibration decoded;
  lp3500_result result;
  unsigned i;
  result = lp3500_check_frame(bytes, length, LP3500_CALIBRATION_REPORT_SIZE, (uint8_t)LP3500_REPORT_ID_CALIBRATION);
  if (result != LP3500_OK) return result;
  if (bytes[3] != LP3500_HALL_TABLE_POINTS) return LP3500_ERROR_POINT_COUNT;
  decoded.sheath_gain_nm_per_count = lp3500_get_i32(bytes + 4);
  decoded.sheath_offset_um = lp3500_get_i32(bytes + 8);
  decoded.sheath_min_um = lp3500_get_i32(bytes + 12);
  decoded.sheath_max_um = lp3500_get_i32(bytes + 16);
  for (i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    decoded.hall_sum[i] = lp3500_get_u16(bytes + 20 + 4 * i);
    decoded.loop_um[i] = lp3500_get_u16(bytes + 22 + 4 * i);
  }
  result = lp3500_validate_calibration(&decoded, NULL);
  if (result != LP3500_OK) return result;
  *c = decoded;
  if (last_write_status) *last_write_status = bytes[2];
  return LP3500_OK;
}

/* ---- HID report descriptor ---------------------------------------------------------------- */

/** Vendor-defined (usage page 0xFF00) descriptor: input report 1 (63 data bytes), feature report 2
 * (identity, 63 data bytes), feature report 3 (calibration, 317 data bytes), all opaque bytes. */
static const uint8_t lp3500_report_descriptor[] = {
    0x06, 0x00, 0xFF,        /* Usage Page (Vendor Defined 0xFF00) */
    0x09, 0x01,              /* Usage (0x01: Resecto LP3500) */
    0xA1, 0x01,              /* Collection (Application) */
    0x15, 0x00,              /*   Logical Minimum (0) */
    0x26, 0xFF, 0x00,        /*   Logical Maximum (255) */
    0x75, 0x08,              /*   Report Size (8 bits) */
    0x85, 0x01,              /*   Report ID (1: input) */
    0x09, 0x02,              /*   Usage (0x02) */
    0x95, 0x3F,              /*   Report Count (63) */
    0x81, 0x02,              /*   Input (Data, Variable, Absolute) */
    0x85, 0x02,              /*   Report ID (2: identity) */
    0x09, 0x03,              /*   Usage (0x03) */
    0x95, 0x3F,              /*   Report Count (63) */
    0xB1, 0x02,              /*   Feature (Data, Variable, Absolute) */
    0x85, 0x03,              /*   Report ID (3: calibration) */
    0x09, 0x04,              /*   Usage (0x04) */
    0x96, 0x3D, 0x01,        /*   Report Count (317) */
    0xB1, 0x02,              /*   Feature (Data, Variable, Absolute) */
    0xC0                     /* End Collection */
};

#ifdef __cplusplus
}  /* extern "C" */
#endif

#endif /* RESECTO_LP3500_PROTOCOL_H */
