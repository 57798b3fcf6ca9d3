#include "continuation/methods/switching.hpp"

#include <fmt/format.h>

#include "continuation/methods/pseudo_arclength.hpp"

namespace backbone::continuation {

namespace {

// After the natural part (`result.branch`, whose points may begin after the saved point `from`
// of a restart): when it ended at the step floor with a point before its last, pseudo-arclength
// takes over from its last point along the secant of its last two, numbering on (its first
// point, that last point corrected again, is not reported twice).
void hand_over(SwitchingBranch& result, const core::Problem& problem, const LoopState* from,
               const NaturalParameter& parameter, core::Corrector& corrector,
               const ContinuationOptions& options, const ContinuationHooks& hooks) {
  Branch& branch = result.branch;
  if (branch.reason != StopReason::step_floor) return;
  // The last two points of the natural part, the saved point of a restart included.
  std::vector<std::pair<int, core::Vector>> tail;
  if (from && from->previous_step != 0)
    tail.emplace_back(from->index - 1, from->previous.cwiseProduct(from->scale));
  if (from && (branch.points.empty() || branch.points.front().index != from->index))
    tail.emplace_back(from->index, from->unknowns());
  for (const BranchPoint& p : branch.points) tail.emplace_back(p.index, p.x);
  if (tail.size() < 2) return;
  const int count = tail.back().first + 1;  // points of the natural part
  if (count >= options.max_points) return;
  const core::Vector last_x = tail.back().second;
  const core::Vector secant = last_x - tail[tail.size() - 2].second;
  const double last_arclength =
      branch.points.empty() ? from->arclength : branch.points.back().arclength;
  const std::string natural_message = branch.message;
  ContinuationOptions rest = options;
  rest.method = Method::arclength;
  const int first = count - 1;  // the arclength run's point 0 is our last point
  ContinuationHooks inner = hooks;
  if (hooks.on_point)
    inner.on_point = [&](const BranchPoint& p) {
      if (p.index != first) hooks.on_point(p);
    };
  Branch arclength = pseudo_arclength(problem, last_x, secant, corrector, rest, inner,
                                      {first, last_arclength, count, branch.rejected_corrections});
  if (arclength.points.size() > 1) result.switch_index = count;
  for (BranchPoint& p : arclength.points)
    if (p.index != first) branch.points.push_back(std::move(p));
  branch.reason = arclength.reason;
  branch.rejected_corrections = arclength.rejected_corrections;
  branch.message = fmt::format(
      "natural in {} for points 0..{} ({}); pseudo-arclength from point "
      "{}: {}",
      parameter.name, count - 1, natural_message, count, arclength.message);
  for (BranchPointReport& r : arclength.branch_points) branch.branch_points.push_back(std::move(r));
}

}  // namespace

SwitchingBranch natural_then_arclength(const core::Problem& problem, const core::Vector& guess,
                                       const NaturalParameter& parameter,
                                       core::Corrector& corrector,
                                       const ContinuationOptions& options,
                                       const ContinuationHooks& hooks, const BranchStart& start) {
  SwitchingBranch result;
  result.branch = natural(problem, guess, parameter, corrector, options, hooks, start);
  hand_over(result, problem, nullptr, parameter, corrector, options, hooks);
  return result;
}

SwitchingBranch natural_then_arclength(const core::Problem& problem, const LoopState& from,
                                       bool record_from, const NaturalParameter& parameter,
                                       core::Corrector& corrector,
                                       const ContinuationOptions& options,
                                       const ContinuationHooks& hooks) {
  SwitchingBranch result;
  if (from.switch_index >= 0) {
    ContinuationOptions rest = options;
    rest.method = Method::arclength;
    result.branch = pseudo_arclength(problem, from, record_from, corrector, rest, hooks);
    result.switch_index = from.switch_index;
    result.branch.message =
        fmt::format("pseudo-arclength from point {}: {}", from.switch_index, result.branch.message);
    return result;
  }
  result.branch = natural(problem, from, record_from, parameter, corrector, options, hooks);
  hand_over(result, problem, &from, parameter, corrector, options, hooks);
  return result;
}

}  // namespace backbone::continuation
