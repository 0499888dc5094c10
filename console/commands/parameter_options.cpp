// The shared `--set` option of simulating commands.
#include "console/commands/parameter_options.h"

#include <stdexcept>

#include "console/commands/checked_options.h"

namespace resecto::cli {

void add_parameter_option(CLI::App& command, std::vector<std::string>& assignments) {
  command.add_option("--set", assignments, "Set a live parameter, KEY=VALUE in the units of `resecto params` (repeatable)")
      ->check(parameter_assignment())
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
}

TissueParameters parameters_from_assignments(const std::vector<std::string>& assignments, const TissueParameters& base) {
  TissueParameters parameters = base;
  for (const std::string& assignment : assignments) {
    if (Status status = parameters.set_from_assignment(assignment); !status) throw std::runtime_error(status.error());
  }
  return parameters;
}

}  // namespace resecto::cli
