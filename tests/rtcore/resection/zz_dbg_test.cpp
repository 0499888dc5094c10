#include <gtest/gtest.h>
#include <cstdio>
#include <cstdlib>
#include "tests/support/procedure_input.h"
namespace resecto {
TEST(Dbg, Turp) {
  SimulationConfig config; config.prostate_triangles = std::atoi(std::getenv("TRI") ? std::getenv("TRI") : "1296");
  auto sim = Simulation::create(config);
  Procedure p = *builtin_procedure("turp");
  const double tick_s = config.tick_s();
  const auto ticks = static_cast<std::uint64_t>(p.duration_s() / tick_s);
  for (std::uint64_t tick = 0; tick < ticks; ++tick) {
    (*sim)->step(procedure_input(p, tick, tick_s), {});
    if (tick % 1920 == 0 || tick + 1 == ticks) { const ProcedureMetrics& m = (*sim)->metrics();
      std::printf("t %.1f resected ad %.2f cap %.3f frac %.3f chips %llu perf %llu sph %llu refined %llu nodes %zu tets %zu refus %llu\n", tick*tick_s, m.resected_adenoma_g, m.resected_capsule_g, m.remaining_adenoma_fraction, (unsigned long long)m.chips, (unsigned long long)m.perforations, (unsigned long long)m.sphincter_zone_violations, (unsigned long long)m.refined_tetrahedra, (*sim)->tissue().node_count(), (*sim)->tissue().topology().live_count(), (unsigned long long)m.topology_refusals); fflush(stdout);}
  }
  for (auto& s : (*sim)->resection().stats().perforation_sites) std::printf("perf at %.1f %.1f %.1f mm\n", s.x*1e3, s.y*1e3, s.z*1e3);
}
}
