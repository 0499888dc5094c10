// What to change when a real-time run could not keep its deadlines: on a machine slower than the
// one the defaults were set on, the physics step outgrows its tick, and the run misses several
// ticks in a hundred. The headless report and the console say so, and name the physics rate at which the run's
// own ticks would have fit, so a person need not find the option by trial.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "rtcore/core/simulation.h"

namespace resecto {

/// Misses above this fraction of the ticks are more than a machine's scheduling jitter (its floor,
/// `deadline_floor_bench`, is a few tenths of a percent on the machines measured): the run itself
/// did not fit.
inline constexpr double kAdviceMissFraction = 0.01;
/// The part of a tick the advice lets the tick's p99 fill: room for the jitter the p99 does not see.
inline constexpr double kAdviceTickShare = 0.75;

/// What the advice reads of a real-time run.
struct RealtimeFigures {
  double miss_fraction = 0.0;
  double tick_p99_us = 0.0;  ///< the whole tick's p99 (the profiler's `tick` stage)
  double collision_hz = 60.0;
  std::int64_t substeps = 16;  ///< physics steps per collision step
  std::uint64_t surface_triangles = 0;
};

/// The substeps realtime_advice() names: the fewest halvings of `run.substeps` at which the run's
/// tick p99 fills at most kAdviceTickShare of the longer tick. 0 when the run kept its deadlines, when
/// its tick p99 fits the rate it ran (the misses were not the tick's cost), or not even one substep would fit.
std::int64_t advised_substeps(const RealtimeFigures& run);

/// Empty for a run that kept its deadlines (misses at most kAdviceMissFraction). Otherwise a
/// sentence: that the ticks fit the rate run (so nothing slower is advised), or the fewest halvings of
/// --substeps at which the run's tick p99 fills at most kAdviceTickShare of the longer tick, or, when
/// not even one physics step per collision step would fit, a coarser gland.
std::string realtime_advice(const RealtimeFigures& run);

/// The figures of a running simulation (its rates and gland) with its deadlines so far.
RealtimeFigures realtime_figures(const Simulation& sim, double miss_fraction, double tick_p99_us);

/// What the advice reads of a `resecto run --headless` report (`deadlines`, `stages.tick`,
/// `rates_hz`, `model`).
RealtimeFigures realtime_figures(const nlohmann::ordered_json& report);

}  // namespace resecto
