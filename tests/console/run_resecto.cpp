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

CommandOutput run_resecto_bounded(const std::string& arguments, double seconds, int megabytes, const std::string& stdout_target) {
  static int counter = 0;
  const std::filesystem::path dir = scratch_directory("run_resecto_bounded_" + std::to_string(++counter));
  const auto out_path = stdout_target.empty() ? (dir / "stdout.txt").string() : stdout_target;
  const auto err_path = dir / "stderr.txt";
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  const std::string memory_cap;  // sanitizers reserve far more address space than they use
  (void)megabytes;
  seconds *= 4;  // and run several times slower
#else
  const std::string memory_cap = "ulimit -v " + std::to_string(megabytes * 1024) + " && ";
#endif
  const std::string command = "sh -c '" + memory_cap + "exec timeout -s KILL " + std::to_string(seconds) + " " +
                              std::string(RESECTO_EXE) + " " + arguments + " >" + out_path + " 2>" + err_path.string() +
                              " </dev/null'";
  const int status = std::system(command.c_str());
  CommandOutput result;
  // timeout's own exit status for a killed child is 128 + 9; a crash is 128 + its signal.
  result.exit_code = WIFEXITED(status) && WEXITSTATUS(status) < 128 ? WEXITSTATUS(status) : -1;
  if (stdout_target.empty()) result.out = read_text(out_path);
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
