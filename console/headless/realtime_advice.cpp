#include "console/headless/realtime_advice.h"

#include <cmath>
#include <cstdio>

namespace resecto {

namespace {

// Whether the tick's own cost fits the rate run: then the misses were not the tick's doing, and a
// slower rate is no cure (audit 8, G19: "ticks (p99 212 us) do not fit the 1042 us").
bool ticks_fit(const RealtimeFigures& run) {
  return run.tick_p99_us <= kAdviceTickShare * 1e6 / (run.collision_hz * static_cast<double>(run.substeps));
}

}  // namespace

std::int64_t advised_substeps(const RealtimeFigures& run) {
  if (!(run.miss_fraction > kAdviceMissFraction) || ticks_fit(run)) return 0;
  // A physics step costs the same at any rate, so the tick measured here is the tick a slower rate
  // would have; fewer substeps give each one a longer period.
  for (std::int64_t fewer = run.substeps / 2; fewer >= 1; fewer /= 2) {
    if (run.tick_p99_us <= kAdviceTickShare * 1e6 / (run.collision_hz * static_cast<double>(fewer))) return fewer;
  }
  return 0;
}

std::string realtime_advice(const RealtimeFigures& run) {
  if (!(run.miss_fraction > kAdviceMissFraction)) return {};
  char text[512];
  if (ticks_fit(run)) {
    std::snprintf(text, sizeof text,
                  "%.1f%% of the deadlines were missed, but the ticks themselves fit (p99 %.0f us of the %.0f us of %.0f Hz physics): "
                  "the core was kept from running (other programs on the machine, a window opening, a session too short to settle), "
                  "so no slower rate is advised",
                  100.0 * run.miss_fraction, run.tick_p99_us, 1e6 / (run.collision_hz * static_cast<double>(run.substeps)),
                  run.collision_hz * static_cast<double>(run.substeps));
    return text;
  }
  if (const std::int64_t fewer = advised_substeps(run); fewer > 0) {
    const double physics_hz = run.collision_hz * static_cast<double>(run.substeps);
    const double advised_hz = run.collision_hz * static_cast<double>(fewer);
    std::snprintf(text, sizeof text,
                  "%.1f%% of the deadlines were missed: this machine's ticks (p99 %.0f us) do not fit the %.0f us of %.0f Hz physics. "
                  "--substeps %lld (%.0f Hz, a tick every %.0f us) would hold them; the tissue then steps more coarsely, so the "
                  "state hashes differ from this rate's",
                  100.0 * run.miss_fraction, run.tick_p99_us, 1e6 / physics_hz, physics_hz, static_cast<long long>(fewer), advised_hz,
                  1e6 / advised_hz);
    return text;
  }
  std::snprintf(text, sizeof text,
                "%.1f%% of the deadlines were missed: this machine's ticks (p99 %.0f us) do not fit even one physics step per "
                "collision step at %.0f Hz; a coarser gland than %llu triangles (--triangles) or fewer collision steps "
                "(--collision-hz) would be needed",
                100.0 * run.miss_fraction, run.tick_p99_us, run.collision_hz, static_cast<unsigned long long>(run.surface_triangles));
  return text;
}

RealtimeFigures realtime_figures(const Simulation& sim, double miss_fraction, double tick_p99_us) {
  return {.miss_fraction = miss_fraction,
          .tick_p99_us = tick_p99_us,
          .collision_hz = static_cast<double>(sim.config().collision_hz),
          .substeps = sim.config().physics_per_collision,
          .surface_triangles = sim.prostate().surface.triangle_count()};
}

RealtimeFigures realtime_figures(const nlohmann::ordered_json& report) {
  RealtimeFigures run;
  run.miss_fraction = report.at("deadlines").at("miss_fraction").get<double>();
  run.tick_p99_us = report.at("stages").at("tick").at("p99_us").get<double>();
  run.collision_hz = report.at("rates_hz").at("collision").get<double>();
  run.substeps = std::llround(report.at("rates_hz").at("physics").get<double>() / run.collision_hz);
  run.surface_triangles = report.at("model").at("surface_triangles").get<std::uint64_t>();
  return run;
}

}  // namespace resecto
