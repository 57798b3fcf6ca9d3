// The paper's continuation strategy: natural-parameter continuation while it works, then
// pseudo-arclength from where it stopped.
//
// Natural continuation in the period (or the energy) is the natural first choice for a
// backbone, but it cannot pass a fold in its parameter and stalls where the branch turns
// steeply in it. natural_then_arclength runs natural() and, when it ends at the step floor with
// at least two points, restarts pseudo_arclength() from its last point in the direction of the
// secant through its last two, for the remaining max_points. The result is one branch: indices
// and arclength continue across the switch (both loops measure it in the same scaled units,
// options.hpp), switch_index says where it happened (-1: natural reached its planned end), and
// the message says both parts. Continued from a saved loop state (restart.hpp), it goes on with
// the part that saved it (the state's switch_index says which).
//
//   NaturalParameter T = NaturalParameter::of_unknown(problem.period_index(), "period", -1.0);
//   SwitchingBranch b = natural_then_arclength(problem, guess, T, *newton, options, hooks);
//   // b.branch.points[0 .. b.switch_index - 1] natural, the rest pseudo-arclength
#pragma once

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/methods/natural.hpp"
#include "continuation/options.hpp"
#include "continuation/restart.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation {

struct SwitchingBranch {
  Branch branch;
  int switch_index = -1;  // first point computed by pseudo-arclength; -1 when none was
};

// Throws core::InputError like natural() and pseudo_arclength(). Never throws on numerical
// failure.
SwitchingBranch natural_then_arclength(const core::Problem& problem, const core::Vector& guess,
                                       const NaturalParameter& parameter,
                                       core::Corrector& corrector,
                                       const ContinuationOptions& options,
                                       const ContinuationHooks& hooks = {},
                                       const BranchStart& start = {});
SwitchingBranch natural_then_arclength(const core::Problem& problem, const LoopState& from,
                                       bool record_from, const NaturalParameter& parameter,
                                       core::Corrector& corrector,
                                       const ContinuationOptions& options,
                                       const ContinuationHooks& hooks = {});

}  // namespace backbone::continuation
