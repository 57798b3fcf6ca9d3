// Callbacks of a continuation run: the loop prints nothing, it calls back.
//
// on_point is called once per accepted point (the first, corrected guess included), in order;
// a reporter prints a line, appends to a file or plots. on_attempt is called after every
// correction attempt, accepted or not, so a progress display can show rejected steps.
// cancel_requested, when set, is polled before each step: returning true ends the branch with
// StopReason::cancelled (e.g. a wall-clock budget). reject_point, when set, is an independent
// check of every converged correction, the first point and a point landed on a bound included
// (x in the problem's own unknowns): a non-empty answer (the reason) rejects it like a failed
// correction, so ds shrinks and the step is retried (a rejected first point ends the branch). A
// shooting residual projected on few test functions can have spurious roots; an exact
// re-simulation of the orbit catches them. on_branch_point and describe_branch_point serve the
// branch-point detection (branch_points.hpp).
//
//   ContinuationHooks hooks;
//   hooks.on_point = [](const BranchPoint& p) {
//     fmt::print("{:4d}  E = {:.6g}  dim {}\n", p.index, p.observable("energy"), p.dimension);
//   };
//   hooks.on_attempt = [](const StepAttempt& a) { if (!a.accepted) ++rejections; };
//   Branch b = pseudo_arclength(problem, x0, hint, *newton, options, hooks);
#pragma once

#include <functional>
#include <string>

#include "continuation/branch.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation {

struct StepAttempt {
  int point = 0;  // index the point would get if accepted
  double ds = 0;  // step size tried
  bool accepted = false;
  core::NewtonSummary newton;  // of the augmented system
  std::string rejection;       // why reject_point refused a converged correction, else empty
};

struct ContinuationHooks {
  std::function<void(const BranchPoint&)> on_point;
  std::function<void(const StepAttempt&)> on_attempt;
  std::function<bool()> cancel_requested;
  std::function<std::string(const core::Vector& x)> reject_point;
  // With options.branch_points.detect: called once per located candidate, in order.
  std::function<void(const BranchPointReport&)> on_branch_point;
  // With options.branch_points.detect: the brackets located or given up so far, whenever that
  // count changes (a resumed loop's first call gives its restored count), after the
  // on_branch_point calls of those brackets: what a saved list of candidates is complete up to
  // (restart.hpp, LoopState::brackets). On the loop's thread.
  std::function<void(int settled)> on_brackets_settled;
  // Describes a verified branch point from the located point on the branch and a point of the
  // attached family near it (both in the problem's own unknowns), e.g. the frequency ratio of the
  // attached family's extra content measured from a simulation: its observables go to
  // BranchPointReport::attached_description (columns of branch_points.csv).
  std::function<core::Observables(const core::Vector& on_branch, const core::Vector& attached)>
      describe_branch_point;
};

}  // namespace backbone::continuation
