// Reading back the landmarks file `mesh prostate` writes beside a mesh: the urethral channel's axis
// (apex to bladder neck) that `mesh tetra` uses. Strict: both points finite, within reach, distinct.
#pragma once

#include <string>
#include <utility>

#include "rtcore/base/result.h"
#include "rtcore/geometry/vec3.h"

namespace resecto {

/// Largest landmark coordinate read, in millimetres on each axis.
inline constexpr double kMaxLandmarkMm = 1000.0;
/// The apex and the bladder neck must be at least this far apart, in millimetres.
inline constexpr double kMinChannelLengthMm = 1.0;

/// The channel axis (apex, bladder neck) in metres from the landmarks JSON text (millimetres).
Result<std::pair<Vec3, Vec3>> parse_channel_axis(const std::string& text, const std::string& source);

}  // namespace resecto
