// Unit conversions at the edges. The core is SI (metres, kilograms, seconds); files, the command line
// and the console speak millimetres, grams and degrees. Every conversion goes through here.
#pragma once

#include <numbers>

namespace resecto::units {

inline constexpr double kMetresPerMillimetre = 1e-3;
inline constexpr double kMillimetresPerMetre = 1e3;
inline constexpr double kKilogramsPerGram = 1e-3;
inline constexpr double kGramsPerKilogram = 1e3;

constexpr double mm_to_m(double mm) { return mm * kMetresPerMillimetre; }
constexpr double m_to_mm(double m) { return m * kMillimetresPerMetre; }
constexpr double deg_to_rad(double deg) { return deg * (std::numbers::pi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / std::numbers::pi); }
/// Cubic metres to millilitres (cm^3).
constexpr double m3_to_ml(double m3) { return m3 * 1e6; }

}  // namespace resecto::units
