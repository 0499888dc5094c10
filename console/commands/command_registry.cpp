// The list of subcommand families, filled during static initialisation.
#include "console/commands/command_registry.h"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace resecto::cli {
namespace {

std::vector<std::pair<std::string, CommandRegistrar>>& registry() {
  static std::vector<std::pair<std::string, CommandRegistrar>> families;
  return families;
}

}  // namespace

RegisterCommand::RegisterCommand(const char* name, CommandRegistrar registrar) {
  registry().emplace_back(name, registrar);
}

CLI::App& subcommand_family(CLI::App& app, const std::string& name, const std::string& description) {
  for (CLI::App* existing : app.get_subcommands({})) {
    if (existing->get_name() == name) return *existing;
  }
  CLI::App* family = app.add_subcommand(name, description);
  family->require_subcommand(1);
  return *family;
}

void register_all_commands(CLI::App& app) {
  auto families = registry();
  std::sort(families.begin(), families.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& family : families) family.second(app);
}

}  // namespace resecto::cli
