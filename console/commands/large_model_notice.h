// A line on standard error before work that takes minutes and gigabytes at the sizes a user may ask
// for (`--triangles 1000000`, a third-party surface of millions of triangles): without it the command
// sat silent for minutes while its memory grew (audit 31, F7).
#pragma once

#include <cstddef>

namespace resecto::cli {

/// Models past this many surface triangles get the notice (138,240 builds in about 10 s).
inline constexpr std::size_t kLargeModelTriangles = 200'000;

/// "note: building a gland of N surface triangles takes a while ..." when `triangles` is past
/// kLargeModelTriangles; `what` says what is built ("a gland", "TetGen's tetrahedra for").
void note_large_model(std::size_t triangles, const char* what);

}  // namespace resecto::cli
