// Runs the `resecto` executable the way a user would, capturing its exit code and output, for the
// end-to-end tests.
#pragma once

#include <filesystem>
#include <string>

namespace resecto::testing {

struct CommandOutput {
  int exit_code = -1;
  std::string out;  ///< standard output
  std::string err;  ///< standard error
};

/// Runs `resecto <arguments>` through the shell (arguments are passed as written).
CommandOutput run_resecto(const std::string& arguments);

/// A fresh empty directory under the build tree for one test's files.
std::filesystem::path scratch_directory(const std::string& test_name);

std::string read_text(const std::filesystem::path& path);

}  // namespace resecto::testing
