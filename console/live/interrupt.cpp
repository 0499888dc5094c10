#include "console/live/interrupt.h"

#include <atomic>
#include <csignal>

#include <unistd.h>

namespace resecto {
namespace {

std::atomic<int> noted_signal{0};
std::atomic<bool> end_at_once{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the handler may only touch lock-free atomics");

extern "C" void note_signal(int signal_number) {
  if (end_at_once.load(std::memory_order_relaxed)) {
    // Only async-signal-safe calls here: write(2) and _exit(2).
    static constexpr char kMessage[] = "resecto: interrupted while the model was being built; nothing was run or written\n";
    [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
    _exit(128 + signal_number);
  }
  noted_signal.store(signal_number, std::memory_order_relaxed);
}

}  // namespace

void catch_interrupts() {
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_handler = note_signal;
    sigemptyset(&action.sa_mask);
    // SA_RESETHAND: the handler runs once; a second Ctrl-C ends the process as it always did.
    action.sa_flags = SA_RESETHAND | SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    return true;
  }();
  (void)installed;
}

int interrupt_signal() { return noted_signal.load(std::memory_order_relaxed); }

EndAtOnceOnInterrupt::EndAtOnceOnInterrupt() { end_at_once.store(true, std::memory_order_relaxed); }
EndAtOnceOnInterrupt::~EndAtOnceOnInterrupt() { end_at_once.store(false, std::memory_order_relaxed); }

std::string signal_name(int signal_number) {
  switch (signal_number) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "signal " + std::to_string(signal_number);
  }
}

}  // namespace resecto
