// Pseudo-arclength continuation (PALC) of a solution curve F(x) = 0, F: R^n -> R^(n-1), or
// R^m with m >= n - 1 when the system is overdetermined but consistent (rank n - 1 along the
// curve, e.g. a shooting residual sampled on more test functions than unknowns): the eigen
// corrector then solves each step in the least-squares sense, KINSOL refuses (square only).
//
// From a point x_k with unit tangent t_k the predictor is x_k + ds t_k (or the secant
// direction), and the corrector solves F bordered by the arclength row,
//     F(x) = 0,    t_k . (x - x_k) - ds = 0,
// a core::BorderedSystem with one linear row (core/solvers/bordered_system.hpp, the LOCA habit):
// any corrector solves it, KINSOL included, since it is square when m = n - 1. The tangent at a
// point is the solution of [J; t_prev^T] t = [0; 1], normalised: it spans the null space of J and
// keeps the orientation of the previous tangent, so the branch goes through folds without
// reversing. The first point is the guess corrected on the hyperplane through it orthogonal to the
// direction hint. Scaling (ds, step_size and arclength dimensionless, in z = x ./ typical_scale()),
// the first point, the step shrinking, hooks.reject_point and landing on bounds are shared with
// natural continuation (loop_steps.hpp, continuation/README.md); the branch's points are returned
// in the problem's own unknowns. The loop prints nothing (see callbacks.hpp); failures are a
// StopReason.
//
//   auto newton = core::make_corrector("kinsol", core::NewtonOptions{});
//   ContinuationOptions opt; opt.ds = 0.01; opt.ds_max = 0.5; opt.max_points = 60;
//   core::Vector guess(2), hint(2);
//   guess << 0.01, 6.283;  hint << 1.0, 0.0;          // Duffing: start at A = 0.01, A grows
//   Branch b = pseudo_arclength(duffing, guess, hint, *newton, opt, hooks);
//   // b.points[i].x, b.points[i].dimension, b.reason, b.message
//   Branch rest = pseudo_arclength(duffing, *b.points[20].state, false, *newton, opt);  // 21, ...
#pragma once

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "continuation/restart.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation {

// Unit tangent of F = 0 at x oriented like `orientation` (t . orientation > 0): minimum-norm
// solution of [J; orientation^T] t = [0; 1], singular values below relative_threshold *
// sigma_max dropped (so a degenerate J, e.g. the paper's shooting residual, yields the
// orientation's component in the numerical null space rather than noise).
core::EvalStatus curve_tangent(const core::Problem& problem, const core::Vector& x,
                               const core::Vector& orientation, double relative_threshold,
                               core::Vector& tangent);

// The same from the Jacobian J at the point (no evaluation).
core::EvalStatus tangent_from_jacobian(const core::Matrix& J, const core::Vector& orientation,
                                       double relative_threshold, core::Vector& tangent);

// Throws core::InputError for bad options, sizes (guess and direction must have n entries,
// m >= n - 1) or a zero direction. Never throws on numerical failure. start: index and arclength
// of the first point (restart.hpp).
Branch pseudo_arclength(const core::Problem& problem, const core::Vector& guess,
                        const core::Vector& direction, core::Corrector& corrector,
                        const ContinuationOptions& options, const ContinuationHooks& hooks = {},
                        const BranchStart& start = {});

// Continues a branch from the loop state saved with one of its points (BranchPoint::state,
// restart.hpp), bit for bit as the run that saved it: nothing is corrected or re-derived.
// record_from: the saved point is the returned branch's first point (recorded again, its rank
// checked), else the branch begins with the next point. InputError when the state does not fit
// (state_mismatch: size, scale, method).
Branch pseudo_arclength(const core::Problem& problem, const LoopState& from, bool record_from,
                        core::Corrector& corrector, const ContinuationOptions& options,
                        const ContinuationHooks& hooks = {});

}  // namespace backbone::continuation
