// `resecto tissue indent`: the virtual indentation test on the deformable gland, printing the
// force-depth curve (and with --json one summary object) so instructors can calibrate a preset.
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "console/commands/checked_options.h"
#include "console/commands/command_registry.h"
#include "console/commands/parameter_options.h"
#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/base/quantile.h"
#include "rtcore/base/units.h"
#include "rtcore/scenes/indentation.h"

namespace resecto::cli {
namespace {

struct IndentOptions {
  int triangles = 8640;
  double depth_mm = 5.0;
  std::vector<std::string> assignments;
  bool json = false;
};

void run_indent(const IndentOptions& o) {
  IndentationOptions options;
  options.parameters = parameters_from_assignments(o.assignments);
  options.depth_m = units::mm_to_m(o.depth_mm);
  Result<ProstateTissueModel> model = build_prostate_tissue_model(generate_prostate(o.triangles), generate_resectoscope().loop);
  if (!model) throw std::runtime_error(model.error());
  const IndentationResult r = run_indentation(*model, options);
  const double median_us = quantile(r.physics_step_us, 0.5), p99_us = quantile(r.physics_step_us, 0.99);
  if (o.json) {
    nlohmann::json curve = nlohmann::json::array();
    for (const IndentationSample& s : r.curve) curve.push_back({units::m_to_mm(s.depth_m), s.force_n});
    const nlohmann::json out = {
        {"triangles", r.surface_triangles}, {"nodes", r.nodes}, {"tetrahedra", r.tetrahedra}, {"springs", r.springs},
        {"depth_mm", o.depth_mm}, {"peak_force_n", r.peak_force_n},
        {"max_displacement_mm", units::m_to_mm(r.max_displacement_m)}, {"residual_mm", units::m_to_mm(r.residual_m)},
        {"settle_time_s", r.settle_time_s}, {"finite", r.finite}, {"max_kinetic_energy_j", r.max_kinetic_energy_j},
        {"max_escape_mm", units::m_to_mm(r.max_escape_m)},
        {"physics_step_us", {{"median", median_us}, {"p99", p99_us}}},
        {"collision_step_us", {{"median", quantile(r.collision_step_us, 0.5)}, {"p99", quantile(r.collision_step_us, 0.99)}}},
        {"state_hash", [&] { char b[17]; std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(r.final_hash)); return std::string(b); }()},
        {"curve_depth_mm_force_n", curve}};
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("indentation: %zu-triangle prostate (%zu nodes, %zu tetrahedra, %zu springs), loop %.2f mm into the left lobe\n",
                r.surface_triangles, r.nodes, r.tetrahedra, r.springs, o.depth_mm);
    std::printf("%8s %10s %10s\n", "time_s", "depth_mm", "force_n");
    for (std::size_t i = 0; i < r.curve.size(); i += 6) {  // 10 lines a second
      const IndentationSample& s = r.curve[i];
      std::printf("%8.3f %10.3f %10.4f\n", s.time_s, units::m_to_mm(s.depth_m), s.force_n);
    }
    std::printf("peak force %.4f N, max displacement %.3f mm, residual %.4f mm, settled %.2f s after withdrawal\n",
                r.peak_force_n, units::m_to_mm(r.max_displacement_m), units::m_to_mm(r.residual_m), r.settle_time_s);
    std::printf("finite %s, max kinetic energy %.3g J, physics step median %.1f us, p99 %.1f us\n", r.finite ? "yes" : "no",
                r.max_kinetic_energy_j, median_us, p99_us);
  }
  if (!r.finite) throw std::runtime_error("the simulation produced a non-finite state at node " + std::to_string(r.faults.first_non_finite_node));
}

void register_tissue(CLI::App& app) {
  CLI::App& tissue = subcommand_family(app, "tissue", "Deformable tissue tools");
  tissue.require_subcommand(1);
  auto options = std::make_shared<IndentOptions>();
  CLI::App* cmd = tissue.add_subcommand("indent", "Virtual indentation: the loop presses into a lateral lobe for 1 s, holds 1 s, withdraws, relaxes 3 s");
  cmd->add_option("--triangles", options->triangles, "Prostate surface triangles")->transform(whole_in_range(200, 1'000'000))->capture_default_str();
  cmd->add_option("--depth-mm", options->depth_mm, "Indentation depth past first touch, mm")->check(finite_range(0.0, 10.0))->capture_default_str();
  add_parameter_option(*cmd, options->assignments);
  cmd->add_flag("--json", options->json, "One JSON object: peak_force_n, max_displacement_mm, residual_mm, finite, ...");
  cmd->callback([options] { run_indent(*options); });
}

const RegisterCommand kRegister{"tissue", &register_tissue};

}  // namespace
}  // namespace resecto::cli
