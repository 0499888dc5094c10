// `resecto params [--json]`: every live tissue parameter with its unit, default and range.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "console/commands/command_registry.h"
#include "rtcore/tissue/tissue_parameters.h"

namespace resecto::cli {
namespace {

void register_params(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("params", "List the live tissue parameters: key, unit, default, range, description");
  cmd->add_flag("--json", *json, "One JSON list of {key, unit, default, min, max, description}");
  cmd->callback([json] {
    if (*json) {
      nlohmann::json list = nlohmann::json::array();
      for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
        list.push_back({{"key", spec.key}, {"unit", spec.unit}, {"default", spec.default_value}, {"min", spec.min_value},
                        {"max", spec.max_value}, {"description", spec.description}});
      }
      std::printf("%s\n", list.dump(2).c_str());
      return;
    }
    std::printf("%-18s %-8s %10s %10s %10s  %s\n", "key", "unit", "default", "min", "max", "description");
    for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
      std::printf("%-18.*s %-8.*s %10g %10g %10g  %.*s\n", static_cast<int>(spec.key.size()), spec.key.data(),
                  static_cast<int>(spec.unit.size()), spec.unit.data(), spec.default_value, spec.min_value, spec.max_value,
                  static_cast<int>(spec.description.size()), spec.description.data());
    }
  });
}

const RegisterCommand kRegister{"params", &register_params};

}  // namespace
}  // namespace resecto::cli
