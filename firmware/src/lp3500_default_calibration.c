/* The compiled-in calibration the board runs on until the host writes one: sheath from the paper's
 * stated range, Hall table from the reference magnet model (firmware/emulator/sensor_model.cpp);
 * tests/firmware checks that the two still agree. */
#include "resecto/lp3500_sensors.h"

/* Sheath: 0 mm at 4.50 V (code 3686.4) and 230 mm at 3.23 V (code 2646.0) on a 5.000 V, 12-bit ADC:
 * gain -221.072 um/count, offset 814.961 mm. The paper's equation 1 (d = -17.386 V + 785.95) has the
 * right slope only read as cm/V and an offset that does not fit its own 0-23 cm range (DESIGN.md), so
 * the default follows the stated range and a real device is calibrated with `resecto device calibrate`.
 * Hall table: points every 0.5 mm over 0-36.5 mm; sums of the two 12-bit codes, rising with travel. */
const lp3500_calibration lp3500_default_calibration = {
    -221072, 814961, 0, 230000,
    {
        2751u, 2937u, 3091u, 3219u, 3327u, 3419u, 3497u, 3564u, 3621u, 3671u,
        3715u, 3754u, 3787u, 3817u, 3844u, 3868u, 3889u, 3908u, 3926u, 3941u,
        3956u, 3969u, 3981u, 3992u, 4003u, 4012u, 4022u, 4030u, 4038u, 4046u,
        4053u, 4060u, 4067u, 4074u, 4080u, 4087u, 4093u, 4099u, 4105u, 4112u,
        4118u, 4125u, 4132u, 4139u, 4146u, 4154u, 4162u, 4170u, 4180u, 4189u,
        4200u, 4211u, 4223u, 4236u, 4251u, 4266u, 4284u, 4303u, 4324u, 4348u,
        4375u, 4405u, 4438u, 4477u, 4521u, 4571u, 4628u, 4695u, 4773u, 4865u,
        4973u, 5101u, 5255u, 5441u,
    },
    {
        0u, 500u, 1000u, 1500u, 2000u, 2500u, 3000u, 3500u, 4000u, 4500u,
        5000u, 5500u, 6000u, 6500u, 7000u, 7500u, 8000u, 8500u, 9000u, 9500u,
        10000u, 10500u, 11000u, 11500u, 12000u, 12500u, 13000u, 13500u, 14000u, 14500u,
        15000u, 15500u, 16000u, 16500u, 17000u, 17500u, 18000u, 18500u, 19000u, 19500u,
        20000u, 20500u, 21000u, 21500u, 22000u, 22500u, 23000u, 23500u, 24000u, 24500u,
        25000u, 25500u, 26000u, 26500u, 27000u, 27500u, 28000u, 28500u, 29000u, 29500u,
        30000u, 30500u, 31000u, 31500u, 32000u, 32500u, 33000u, 33500u, 34000u, 34500u,
        35000u, 35500u, 36000u, 36500u,
    },
};
