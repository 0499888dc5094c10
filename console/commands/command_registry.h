// Self-registration of the `resecto` subcommand families: each commands/*.cpp file declares one
// static RegisterCommand, and main() adds them all, in name order so --help reads the same each time.
#pragma once

#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

namespace resecto::cli {

using CommandRegistrar = void (*)(CLI::App& app);

/// Declare one at namespace scope in a commands/*.cpp file to add a subcommand family.
struct RegisterCommand {
  RegisterCommand(const char* name, CommandRegistrar registrar);
};

/// The subcommand `name` of `app`, created on first use: families that share a prefix (`device list`,
/// `device calibrate`) live in different files and meet here.
CLI::App& subcommand_family(CLI::App& app, const std::string& name, const std::string& description);

/// Ends the running subcommand: main() prints `resecto: <message>` on standard error and exits 1.
[[noreturn]] inline void fail(const std::string& message) { throw std::runtime_error(message); }

/// Adds every registered family to `app`, ordered by name.
void register_all_commands(CLI::App& app);

}  // namespace resecto::cli
