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

/// Runs `resecto <arguments>` as a hostile-input test wants it: killed after `seconds`, with its
/// address space capped at `megabytes` (no cap under AddressSanitizer, which reserves terabytes),
/// standard output to `stdout_target` (a file of the test's own when empty, e.g. "/dev/full").
/// exit_code is -1 when a signal ended it (a crash, or the kill at the time limit).
CommandOutput run_resecto_bounded(const std::string& arguments, double seconds = 5.0, int megabytes = 512,
                                  const std::string& stdout_target = "");

/// A fresh empty directory under the build tree for one test's files.
std::filesystem::path scratch_directory(const std::string& test_name);

std::string read_text(const std::filesystem::path& path);

}  // namespace resecto::testing
