// Golden state hashes: the core's state after fixed scenarios, committed so that any change to the
// numerics shows as one (Box2D's test_determinism.c does the same). Checked by
// tests/console/golden_hash_test.cpp through `resecto run --headless` (batch: the emulated device in
// lockstep, so the run is the same on every machine).
//
// When the test fails:
// - If your change was NOT meant to change the numerics (a refactor, a rename, a speed-up that should
//   give the same bits), it has a bug. To find the first collision step that moved: record the
//   scenario with the build before the change (`resecto run --headless <arguments> --record A.rsr`)
//   and replay it with the build after (`resecto replay A.rsr --verify`).
// - If it was meant to (a new solver term, a changed default, a new order of summation), update the
//   values below from the command in each row's comment, and say in the commit message that the
//   golden hashes moved and why. Keep the scenarios as they are; add one rather than change one.
#pragma once

#include <cstdint>

namespace resecto::testing {

struct GoldenRun {
  const char* arguments;     ///< after `resecto run --headless`
  const char* state_hash;    ///< the report's final `state_hash`
  const char* hash_chain;    ///< the report's `hash_chain` over every collision step
  std::uint64_t cuts;        ///< the report's `metrics.cuts`: shows the scenario still cuts
};

inline constexpr GoldenRun kGoldenRuns[] = {
    // resecto run --headless --procedure demo --seconds 2 --triangles 1296 --json
    // (moved 2026-12-03: the retracted loop lies inside the sheath's beak and takes no part in contact,
    // and strokes close against the sheath)
    {"--procedure demo --seconds 2 --triangles 1296", "a13d5af7150bedc7", "48061b9c7116b613", 0},
    // resecto run --headless --procedure turp --seconds 4 --triangles 1296 --json (one stroke cuts; two
    // before turp's moves between strokes were paced, 2026-11-27, which moved these values; moved again
    // 2026-11-29 when the clearance certificates were made to give the brute-force state at folds, and
    // 2026-12-03 with the demo's row, when turp's strokes came to close against the sheath)
    {"--procedure turp --seconds 4 --triangles 1296", "fc09ab9d22ea6211", "b16855f31214ec0d", 1},
};

}  // namespace resecto::testing
