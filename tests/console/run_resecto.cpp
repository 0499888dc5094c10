// Process helpers for the end-to-end tests.
#include "tests/console/run_resecto.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace resecto::testing {

CommandOutput run_resecto(const std::string& arguments) {
  static int counter = 0;
  const std::filesystem::path dir = scratch_directory("run_resecto_" + std::to_string(++counter));
  const auto out_path = dir / "stdout.txt";
  const auto err_path = dir / "stderr.txt";
  const std::string command = std::string(RESECTO_EXE) + " " + arguments + " >" + out_path.string() +
                              " 2>" + err_path.string() + " </dev/null";
  const int status = std::system(command.c_str());
  CommandOutput result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = read_text(out_path);
  result.err = read_text(err_path);
  return result;
}

std::filesystem::path scratch_directory(const std::string& test_name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("resecto_test_" + std::to_string(::getpid())) / test_name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

}  // namespace resecto::testing
