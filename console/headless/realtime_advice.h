// What to change when a real-time run could not keep its deadlines: on a machine slower than the
// one the defaults were set on, the physics step outgrows its tick, and the run misses a tick in
// twenty. The report says so, and names the physics rate at which this run's own ticks would have
// fit, so a person need not find the option by trial.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace resecto {

/// Misses above this fraction of the ticks are more than a machine's scheduling jitter (its floor,
/// `deadline_floor_bench`, is a few tenths of a percent on the machines measured): the run itself
/// did not fit.
inline constexpr double kAdviceMissFraction = 0.01;
/// The part of a tick the advice lets the tick's p99 fill: room for the jitter the p99 does not see.
inline constexpr double kAdviceTickShare = 0.75;

/// Empty for a batch run, or a real-time run that kept its deadlines (misses at most
/// kAdviceMissFraction). Otherwise a sentence: the fewest halvings of --substeps at which the run's
/// tick p99 fills at most kAdviceTickShare of the longer tick, or, when not even one physics step
/// per collision step would fit, a coarser gland. Reads `mode`, `deadlines`, `stages.tick`,
/// `rates_hz` and `model` of a `resecto run --headless` report.
std::string realtime_advice(const nlohmann::ordered_json& report);

}  // namespace resecto
