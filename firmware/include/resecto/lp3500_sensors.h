/* The board's sensor models in integer arithmetic: the sheath potentiometer's linear model (the paper's
 * equation 1, with calibrated gain and offset) and the loop's summed-Hall lookup table with linear
 * interpolation; plus the compiled-in default calibration. */
#ifndef RESECTO_LP3500_SENSORS_H
#define RESECTO_LP3500_SENSORS_H

#include <stdint.h>

#include "resecto/lp3500_protocol.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The compiled-in calibration (see firmware/README.md, "Default calibration"): sheath 0 mm at 4.50 V
 * and 230 mm at 3.23 V on a 5 V, 12-bit ADC; the Hall table of the reference magnet model. */
extern const lp3500_calibration lp3500_default_calibration;

/** Sheath insertion in micrometres from the sum of `sample_count` potentiometer codes, clamped to the
 * calibrated range; `*clamped` is set to 1 when clamping happened, else 0. `sample_count` >= 1. */
int32_t lp3500_sheath_um(const lp3500_calibration* c, uint32_t code_sum, uint16_t sample_count, uint8_t* clamped);

/** Loop travel in micrometres from the sum over `sample_count` samples of hall_a + hall_b, through
 * the monotone table with linear interpolation, clamped to the table's ends (`*clamped` = 1). */
int32_t lp3500_loop_um(const lp3500_calibration* c, uint32_t hall_sum_total, uint16_t sample_count,
                       uint8_t* clamped);

/** Rounded integer division, halves away from zero; `denominator` > 0. */
int64_t lp3500_divide_rounded(int64_t numerator, int64_t denominator);

#ifdef __cplusplus
}
#endif

#endif /* RESECTO_LP3500_SENSORS_H */
