// The debrief page: one self-contained HTML file (inline SVG, inline CSS, no script, nothing fetched)
// with the metrics against reference figures, plots over time and the resection heat map. With two
// scores the page shows them side by side (trainee and expert).
#pragma once

#include <span>
#include <string>

#include "console/score/rescore.h"

namespace resecto {

/// Colours of the heat map's cells (the screenshot test looks for them).
inline constexpr const char* kRemovedAdenomaColour = "#d62828";
inline constexpr const char* kRemainingAdenomaColour = "#e9c46a";
inline constexpr const char* kRemovedCapsuleColour = "#6a00f4";
inline constexpr const char* kRemainingCapsuleColour = "#c8c8c8";

/// The page for one score, or two side by side.
std::string debrief_html(std::span<const RecordingScore> scores);

/// The heat map alone as an SVG element (axial slices, apex to bladder neck).
std::string heat_map_svg(const ResectionHeatMap& map);

}  // namespace resecto
