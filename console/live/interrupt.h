// Ctrl-C (SIGINT) and SIGTERM end a headless run or the console the way the end of their procedure
// does: the ticks stop, the recording is closed with its index, and the report, trace and surface are
// written, so nothing the run had made is lost and no file is left half written. The handler only
// notes the signal; the run polls it once a tick (one relaxed atomic load: no lock, no system call).
// A second signal ends the process at once, as it would have without the handler.
#pragma once

#include <stdexcept>
#include <string>

namespace resecto {

/// Installs the handlers for SIGINT and SIGTERM (once; later calls do nothing).
void catch_interrupts();

/// The signal noted since catch_interrupts(), or 0.
int interrupt_signal();

/// "SIGINT" or "SIGTERM".
std::string signal_name(int signal_number);

/// While one exists, a signal ends the process at once (exit 128 + its number, after a line on
/// standard error) instead of being noted: for work that writes nothing and cannot poll, such as
/// building a large model, where a noted Ctrl-C would wait minutes for the build to end only to stop
/// the run before its first tick (audit 31, F3).
class EndAtOnceOnInterrupt {
 public:
  EndAtOnceOnInterrupt();
  ~EndAtOnceOnInterrupt();
  EndAtOnceOnInterrupt(const EndAtOnceOnInterrupt&) = delete;
  EndAtOnceOnInterrupt& operator=(const EndAtOnceOnInterrupt&) = delete;
};

/// Thrown after a run that a signal ended has written its outputs: main() prints the message and
/// exits with 128 + the signal's number, the code a shell gives a process the signal killed.
class InterruptedRun : public std::runtime_error {
 public:
  InterruptedRun(int signal_number, const std::string& message) : std::runtime_error(message), signal_number_(signal_number) {}
  int exit_code() const { return 128 + signal_number_; }

 private:
  int signal_number_;
};

}  // namespace resecto
