// The progress line's estimate of the time left: the sooner of the point budget at the current
// rate and the first bound, extrapolated in log for a positive observable.
#include <gtest/gtest.h>

#include "continuation/cli/progress.hpp"

namespace {

using namespace backbone::continuation;
using namespace backbone::cli;

BranchPoint point(int index, double energy) {
  BranchPoint p;
  p.index = index;
  p.observables = {{"energy", energy}, {"frequency", 1.5}};
  return p;
}

TEST(ProgressLine, EtaExtrapolatesTheBoundInLog) {
  ContinuationOptions options;
  options.max_points = 1000;
  options.bounds.push_back({"energy", 0.0, 1e-2});
  ProgressLine progress(options, /*enabled=*/false);
  progress.text(point(0, 1e-4), 0.0);
  // Half way in log (1e-4 -> 1e-3 of 1e-4 -> 1e-2) after 10 s: 10 s left. The point budget
  // (998 points at 0.2 points/s) would take far longer.
  const std::string line = progress.text(point(1, 1e-3), 10.0);
  EXPECT_NE(line.find("ETA 10 s (energy bound 0.01)"), std::string::npos) << line;
  EXPECT_NE(line.find("E 0.001"), std::string::npos) << line;
}

TEST(ProgressLine, EtaFollowsThePointBudgetWithoutBounds) {
  ContinuationOptions options;
  options.max_points = 21;
  ProgressLine progress(options, false);
  progress.text(point(0, 1.0), 0.0);
  // 2 points in 4 s: 0.5 points/s, 19 points left: 38 s.
  const std::string line = progress.text(point(1, 2.0), 4.0);
  EXPECT_NE(line.find("0.5 points/s  ETA 38 s"), std::string::npos) << line;
}

}  // namespace
