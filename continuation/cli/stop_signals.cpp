#include "continuation/cli/stop_signals.hpp"

#include <unistd.h>

namespace backbone::cli {

namespace {

volatile std::sig_atomic_t first_signal = 0;

extern "C" void on_stop_signal(int signal) {
  if (first_signal != 0) {  // the second: the default action, now
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  first_signal = signal;
  static const char message[] =
      "\nbackbone: stopping after the current point (signal again to stop now; --resume "
      "continues from the last point written)\n";
  const ssize_t written = ::write(STDERR_FILENO, message, sizeof message - 1);
  (void)written;
}

}  // namespace

StopSignals::StopSignals() {
  first_signal = 0;
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
}

StopSignals::~StopSignals() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

bool StopSignals::requested() const {
  return first_signal != 0;
}

int StopSignals::signal() const {
  return static_cast<int>(first_signal);
}

}  // namespace backbone::cli
