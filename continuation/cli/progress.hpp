// Progress of a long continuation run, one line on stderr rewritten in place, only when stderr
// is a terminal (quiet in pipes, logs and CI).
//
// The line shows the points so far, the current energy and frequency (when the problem reports
// them), the rate and an estimate of the time left: the sooner of reaching max_points at the
// current rate and reaching the first bound, extrapolating the observable's progress towards it
// (in log for a positive observable, such as an energy).
//
//   ProgressLine progress(options);                 // enabled = isatty(stderr)
//   hooks.on_point = [&](const BranchPoint& p) { ...; progress.update(p); };
//   ... continuation ...
//   progress.finish();                              // clears the line
#pragma once

#include <chrono>
#include <string>

#include "continuation/branch.hpp"
#include "continuation/options.hpp"

namespace backbone::cli {

using continuation::BranchPoint;
using continuation::BranchPointReport;
using continuation::ContinuationOptions;

// One line per accepted point for a log: "point 12 period 3.1 ... dim 1  |F| 2e-11  newton 2
// ds 2  0.021 s".
std::string point_line(const BranchPoint& point);
// One line per located branch-point candidate: "branch point after point 5: period 3.6 ...
// verified, attached dimension 19 (nullity 20) frequency_ratio 8  12 Jacobians  0.055 s", or
// "... not verified (nullity 1) ...".
std::string branch_point_line(const BranchPointReport& report);

class ProgressLine {
 public:
  explicit ProgressLine(const ContinuationOptions& options);
  ProgressLine(const ContinuationOptions& options, bool enabled);
  void update(const BranchPoint& point);
  void finish();
  // The text of the line for a point (what update prints), for tests.
  std::string text(const BranchPoint& point, double elapsed_seconds);

 private:
  const ContinuationOptions& options_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  int points_ = 0;
  double first_value_ = 0;
  bool have_first_ = false;
};

}  // namespace backbone::cli
