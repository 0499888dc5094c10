// The small gland the core's tests step (1296 surface triangles): hundreds of collision steps a
// second, so a test can follow seconds of a procedure.
#pragma once

#include "rtcore/core/simulation.h"

namespace resecto::testing {

inline SimulationConfig small_config() {
  SimulationConfig config;
  config.prostate_triangles = 1296;
  return config;
}

}  // namespace resecto::testing
