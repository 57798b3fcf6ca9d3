#include "continuation/switching.hpp"

#include <fmt/format.h>

#include "continuation/pseudo_arclength.hpp"

namespace backbone::continuation {

SwitchingBranch natural_then_arclength(const core::Problem& problem, const core::Vector& guess,
                                       const NaturalParameter& parameter,
                                       core::Corrector& corrector,
                                       const ContinuationOptions& options,
                                       const ContinuationHooks& hooks) {
  SwitchingBranch result;
  result.branch = natural(problem, guess, parameter, corrector, options, hooks);
  Branch& branch = result.branch;
  const int count = static_cast<int>(branch.points.size());
  if (branch.reason != StopReason::step_floor || count < 2 || count >= options.max_points)
    return result;

  const BranchPoint last = branch.points.back();
  const core::Vector secant = last.x - branch.points[count - 2].x;
  const std::string natural_message = branch.message;
  ContinuationOptions rest = options;
  rest.method = Method::arclength;
  rest.max_points = options.max_points - count + 1;  // its point 0 is our last point
  // The arclength run restarts at our last point: its point 0 is that point again, so it is
  // not reported twice, and later points continue our numbering and arclength.
  ContinuationHooks inner = hooks;
  if (hooks.on_point)
    inner.on_point = [&](const BranchPoint& p) {
      if (p.index == 0) return;
      BranchPoint q = p;
      q.index += count - 1;
      q.arclength += last.arclength;
      hooks.on_point(q);
    };
  if (hooks.on_attempt)
    inner.on_attempt = [&](const StepAttempt& a) {
      StepAttempt b = a;
      b.point += count - 1;
      hooks.on_attempt(b);
    };
  Branch tail = pseudo_arclength(problem, last.x, secant, corrector, rest, inner);
  if (tail.points.size() > 1) result.switch_index = count;  // its point 0 is our last one
  for (BranchPoint& p : tail.points) {
    if (p.index == 0) continue;
    p.index += count - 1;
    p.arclength += last.arclength;
    branch.points.push_back(std::move(p));
  }
  branch.reason = tail.reason;
  branch.message = fmt::format(
      "natural in {} for points 0..{} ({}); pseudo-arclength from point "
      "{}: {}",
      parameter.name, count - 1, natural_message, count, tail.message);
  return result;
}

}  // namespace backbone::continuation
