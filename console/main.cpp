// resecto: the simulator's one executable. Each subcommand family registers itself; a failure prints
// one line on standard error and exits non-zero.
#include <cstdio>
#include <exception>

#include "console/commands/command_registry.h"

int main(int argc, char** argv) {
  CLI::App app{"Resecto: a real-time simulator for training transurethral resection of the prostate"};
  app.require_subcommand(1);
  resecto::cli::register_all_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "resecto: %s\n", e.what());
    return 1;
  }
  return 0;
}
