// `--set KEY=VALUE` (repeatable) for every command that simulates: one place turns the assignments
// into TissueParameters and refuses an unknown key or an out-of-range value with a clear line.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "rtcore/tissue/tissue_parameters.h"

namespace resecto::cli {

/// Adds `--set KEY=VALUE` to `command`; the assignments land in `assignments`.
void add_parameter_option(CLI::App& command, std::vector<std::string>& assignments);

/// `base` (the defaults) with every assignment applied in order; throws std::runtime_error with the first
/// bad assignment's one-line reason (the command's callback turns it into exit 1).
TissueParameters parameters_from_assignments(const std::vector<std::string>& assignments, const TissueParameters& base = {});

}  // namespace resecto::cli
