// The shared `--set` option of simulating commands.
#include "console/commands/parameter_options.h"

#include <map>
#include <stdexcept>
#include <string>

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
  // A parameter set twice kept the last value silently (audit 32, F15), as a preset's repeated key
  // did before presets refused it: which one the author meant is theirs to say.
  std::map<std::string, std::string> given;
  for (const std::string& assignment : assignments) {
    if (Status status = parameters.set_from_assignment(assignment); !status) throw std::runtime_error(status.error());
    const std::string key = assignment.substr(0, assignment.find('='));
    if (const auto [earlier, first] = given.emplace(key, assignment); !first) {
      throw std::runtime_error("--set " + assignment + ": " + key + " is already set by --set " + earlier->second + "; give each parameter once");
    }
  }
  return parameters;
}

}  // namespace resecto::cli
