// The switch at a period doubling onto the branch of twice the period (continuation/README.md,
// 'Stability and bifurcations of orbits').
//
// At a located period doubling x* the monodromy has a real multiplier -1 with eigenvector v (the
// state's part of the unknowns). In the problem of twice the period (FloquetProblem::
// doubled_problem) x* is an orbit where two families cross: the period-1 branch, with tangent t,
// and the doubled one, which leaves along v. The switch steps by eps along w, v made orthogonal
// to t (so that the period-1 branch meets the hyperplane through x* + eps w normal to w only at
// second order), corrects there, and refuses a corrected orbit that is still one of period 1
// (the base residual below the corrector's tolerance); eps is 1e-2 of the state's size, then a
// quarter and a sixteenth of it. From there the doubled branch is traced by pseudo-arclength
// along w, its points carrying their own multipliers.
//
//   DoubledBranch d = follow_period_doubling(problem, found[k], *corrector, options, hooks);
//   if (d.branch.points.empty()) fmt::print("{}\n", d.message);
#pragma once

#include <string>

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "continuation/orbit_bifurcations/bifurcations.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation {

struct DoubledBranch {
  std::unique_ptr<core::Problem> problem;  // the doubled problem the branch belongs to
  core::Vector start;                      // the corrected first orbit (its unknowns)
  Branch branch;                           // empty points when the switch failed
  std::string message;                     // why it did not start, else the branch's message
};

// hooks.on_point sees every point of the doubled branch (BranchWriter). Never throws on
// numerical failure.
DoubledBranch follow_period_doubling(const core::Problem& problem, const OrbitBifurcation& doubling,
                                     core::Corrector& corrector, const ContinuationOptions& options,
                                     const ContinuationHooks& hooks = {});

}  // namespace backbone::continuation
