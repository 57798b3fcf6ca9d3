// SIGINT and SIGTERM for a long run: the first asks it to stop after the current point, the
// second stops the process at once (its default action, exit status 128 + the signal).
//
//   StopSignals stop;                                  // installs the handlers
//   hooks.cancel_requested = [&] { return stop.requested(); };
//   ... run ...
//   if (stop.requested()) return 128 + stop.signal();  // handlers restored by the destructor
//
// A point can take minutes (a many-dimensional start on a fine grid, problems/contact_bar/bench/
// README.md 'Cost'), and a run writes each point as soon as it is accepted, so a
// second signal loses only the point under way: `trace --resume` continues from the last one
// written. The first signal prints one line saying so (write(2), safe in a handler).
#pragma once

#include <csignal>

namespace backbone::cli {

class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  bool requested() const;
  int signal() const;  // the first signal received, 0 if none
};

}  // namespace backbone::cli
