#include "console/headless/realtime_advice.h"

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace resecto {

std::string realtime_advice(const nlohmann::ordered_json& report) {
  if (report.at("mode") != "realtime") return {};
  const double missed = report.at("deadlines").at("miss_fraction").get<double>();
  if (!(missed > kAdviceMissFraction)) return {};
  const double tick_p99_us = report.at("stages").at("tick").at("p99_us").get<double>();
  const double physics_hz = report.at("rates_hz").at("physics").get<double>();
  const double collision_hz = report.at("rates_hz").at("collision").get<double>();
  const auto substeps = static_cast<std::int64_t>(std::llround(physics_hz / collision_hz));
  char text[512];
  // A physics step costs the same at any rate, so the tick measured here is the tick a slower rate
  // would have; fewer substeps give each one a longer period.
  for (std::int64_t fewer = substeps / 2; fewer >= 1; fewer /= 2) {
    const double period_us = 1e6 / (collision_hz * static_cast<double>(fewer));
    if (tick_p99_us <= kAdviceTickShare * period_us) {
      std::snprintf(text, sizeof text,
                    "%.1f%% of the deadlines were missed: this machine's ticks (p99 %.0f us) do not fit the %.0f us of %.0f Hz physics. "
                    "--substeps %lld (%.0f Hz, a tick every %.0f us) would hold them; the tissue then steps more coarsely, so the "
                    "state hashes differ from this rate's",
                    100.0 * missed, tick_p99_us, 1e6 / physics_hz, physics_hz, static_cast<long long>(fewer),
                    collision_hz * static_cast<double>(fewer), period_us);
      return text;
    }
  }
  const auto triangles = report.at("model").at("surface_triangles").get<std::uint64_t>();
  std::snprintf(text, sizeof text,
                "%.1f%% of the deadlines were missed: this machine's ticks (p99 %.0f us) do not fit even one physics step per "
                "collision step at %.0f Hz; a coarser gland than %llu triangles (--triangles) or fewer collision steps "
                "(--collision-hz) would be needed",
                100.0 * missed, tick_p99_us, collision_hz, static_cast<unsigned long long>(triangles));
  return text;
}

}  // namespace resecto
