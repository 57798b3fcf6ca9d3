// Internal to backbone::continuation: what both continuation loops do with a corrected point.
//
// PointRecorder measures the cost of a point (wall time, evaluations of the base problem since
// begin()), evaluates its observables and residual, runs the rank report (+ verification, with
// the corrector options.verification describes: core::make_verifier) when due, and checks the
// bounds. A verified dimension below 1 contradicts the curve the loop follows: it is re-checked
// along the curve's direction (the tangent or chord the loop knows, branch.hpp: DimensionFlag).
// Keeping this in one place makes natural and pseudo-arclength branches record exactly the
// same columns; loop_steps.hpp drives it for both loops.
//
//   PointRecorder rec(problem, options);
//   rec.begin();
//   ... predict, correct ...
//   BranchPoint p = rec.finish(x, index, newton_iterations, ds, arclength, /*last=*/false,
//                              tangent);
//   double value;
//   if (const Bound* b = rec.violated_bound(p, value)) { ... }
#pragma once

#include <chrono>
#include <limits>
#include <memory>
#include <string>

#include "continuation/branch.hpp"
#include "continuation/options.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation {

class PointRecorder {
 public:
  // counted: the problem whose evaluation counters measure the cost (the base problem when
  // `problem` is a view of it, e.g. ScaledProblem, whose FD Jacobian calls only the base).
  PointRecorder(const core::Problem& problem, const ContinuationOptions& options,
                const core::Problem* counted = nullptr);
  void begin();
  // Fills a BranchPoint; runs the rank report when index % rank_check_every == 0 or force_rank.
  // curve_direction: the direction of the traced curve at x (empty: unknown), for the re-check.
  // previous: the branch's point before x (nullptr: none), a known neighbour for the
  // verification (core::verify_null_directions).
  BranchPoint finish(const core::Vector& x, int index, int newton_iterations, double ds,
                     double arclength, bool force_rank, const core::Vector& curve_direction = {},
                     const core::Vector* previous = nullptr);
  // Rank report (and verification) at an already recorded point.
  void check_rank(BranchPoint& point, const core::Vector& curve_direction = {},
                  const core::Vector* previous = nullptr);
  // While set, finish() computes the rank report without verifying its null directions
  // (BranchPoint::dimension is then the nullity); verify_deferred() does that later.
  void defer_verification(bool defer) { defer_ = defer; }
  // Verifies a report finish() deferred, with `neighbour` (the point recorded last, whose ||F||
  // is known: no evaluation when it confirms a direction) or by probes when null, then the
  // re-check along curve_direction.
  void verify_deferred(BranchPoint& point, const core::Vector& curve_direction,
                       const core::Vector* neighbour);
  // With a verified dimension below 1 and a verifier: probes curve_direction; when it is real,
  // the dimension is 1 plus the verified candidate directions orthogonal to it (flag
  // rechecked), else the flag says unconfirmed. Nothing happens at a point of dimension >= 1.
  // jacobian: J at point.x when the caller has it (the probes then start with chord steps on
  // it, ContinuationOptions::chord_corrections).
  void recheck_dimension(BranchPoint& point, const core::Vector& curve_direction,
                         const core::Matrix* jacobian = nullptr,
                         const core::Vector* previous = nullptr);
  // With options.boundary.verify_inside, at a point on the boundary of its solution set (the
  // boundary observable at most `within`) F may not be differentiable, and J is one side's: its
  // nullity can miss the directions across the boundary. With a verifier, the chord towards the
  // anchor (the branch's point 0 when it is inside: a boundary whose candidates all run along it,
  // a face of a family of several dimensions, is crossed by that chord) and the point's
  // candidates are probed on either side; the neighbour that re-corrects with the largest
  // observable (above the point's) is inside, and its rank report, verified, replaces the
  // point's when its dimension is larger (flag inside: nullity and singular values are then the
  // neighbour's). Nothing happens elsewhere.
  void recheck_inside(BranchPoint& point);
  // The point's multipliers (BranchPoint::floquet) when the problem is a core::FloquetProblem
  // and options.stability holds.
  void add_floquet(BranchPoint& point) const;
  // First bound the point violates, or nullptr; `value` receives the bound value crossed.
  const Bound* violated_bound(const BranchPoint& point, double& value) const;
  double elapsed_seconds() const;
  // Takes x as the last recorded point (its residual evaluated now): a resumed loop's saved
  // point, which finish() recorded in the earlier run.
  void remember(const core::Vector& x);

 private:
  double residual_norm(const core::Vector& x) const;  // ||F(x)||_inf, NaN when F fails
  // The recorder's problem's x (a ScaledProblem's z) to the base problem's unknowns, and back.
  core::Vector to_unknowns(const core::Vector& x) const;
  core::Vector from_unknowns(const core::Vector& unknowns) const;
  // ||F(x)||_inf when x is the last point finish() recorded (the branch's previous point, the
  // verification's known neighbour), else NaN.
  double known_residual(const core::Vector* x) const;

  bool defer_ = false;
  const core::Problem& problem_;
  const core::Problem& counted_;
  const ContinuationOptions& options_;
  std::unique_ptr<core::Corrector> verifier_;  // eigen: handles non-square constrained systems
  std::chrono::steady_clock::time_point start_;
  long residuals_at_start_ = 0, jacobians_at_start_ = 0;
  core::Vector anchor_;  // point 0 in the base unknowns when inside, else empty
  core::Vector last_x_;  // the last recorded point and its residual norm
  double last_residual_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace backbone::continuation
