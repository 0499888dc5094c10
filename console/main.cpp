// resecto: the simulator's one executable. Each subcommand family registers itself; a failure prints
// one line on standard error and exits non-zero.
#include <cstdio>
#include <exception>

#include "console/commands/command_registry.h"
#include "console/live/interrupt.h"
#include "rtcore/base/atomic_file.h"

int main(int argc, char** argv) {
  CLI::App app{"Resecto: a real-time simulator for training transurethral resection of the prostate"};
  app.require_subcommand(1);
  resecto::cli::register_all_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print and succeed; any other command line that cannot be parsed (a
    // missing file, an unknown option, a value out of range) is a usage error: 2, as for most Unix
    // tools, rather than CLI11's own codes (105 to 109) that scripts would have to learn.
    if (app.exit(e) != 0) return 2;
    // Help printed into a full disk or a closed pipe is lost as a report would be (audit 32, F15).
    if (resecto::Status flushed = resecto::flush_standard_output(); !flushed) {
      std::fprintf(stderr, "resecto: %s\n", flushed.error().c_str());
      return 1;
    }
    return 0;
  } catch (const resecto::InterruptedRun& e) {
    // The run stopped early but wrote everything it had: its outputs are whole, the exit code a
    // shell's for the signal.
    resecto::Status flushed = resecto::flush_standard_output();
    std::fprintf(stderr, "resecto: %s\n", e.what());
    if (!flushed) std::fprintf(stderr, "resecto: %s\n", flushed.error().c_str());
    return e.exit_code();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "resecto: %s\n", e.what());
    return 1;
  }
  // A report printed into a full disk or a closed pipe is lost: that is a failure, not exit 0.
  if (resecto::Status flushed = resecto::flush_standard_output(); !flushed) {
    std::fprintf(stderr, "resecto: %s\n", flushed.error().c_str());
    return 1;
  }
  return 0;
}
