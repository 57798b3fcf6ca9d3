// Internal to backbone::continuation: what both continuation loops do with a corrected point.
//
// PointRecorder measures the cost of a point (wall time, evaluations of the base problem since
// begin()), evaluates its observables and residual, runs the rank report (+ verification) when
// due, and checks the bounds. Keeping this in one place makes natural and pseudo-arclength
// branches record exactly the same columns.
//
//   PointRecorder rec(problem, options);
//   rec.begin();
//   ... predict, correct ...
//   BranchPoint p = rec.finish(x, index, newton_iterations, ds, arclength, /*last=*/false);
//   if (const Bound* b = rec.violated_bound(p)) { ... }
#pragma once

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "core/newton.hpp"
#include "core/problem.hpp"

namespace backbone::continuation {

class PointRecorder {
 public:
  // counted: the problem whose evaluation counters measure the cost (the base problem when
  // `problem` is a view of it, e.g. ScaledProblem, whose FD Jacobian calls only the base).
  PointRecorder(const core::Problem& problem, const ContinuationOptions& options,
                const core::Problem* counted = nullptr);
  void begin();
  // Fills a BranchPoint; runs the rank report when index % rank_check_every == 0 or force_rank.
  BranchPoint finish(const core::Vector& x, int index, int newton_iterations, double ds,
                     double arclength, bool force_rank);
  // Rank report (and verification) at an already recorded point.
  void check_rank(BranchPoint& point);
  // First bound the point violates, or nullptr; `value` receives the bound value crossed.
  const Bound* violated_bound(const BranchPoint& point, double& value) const;
  double elapsed_seconds() const;

 private:
  const core::Problem& problem_;
  const core::Problem& counted_;
  const ContinuationOptions& options_;
  std::unique_ptr<core::Corrector> verifier_;  // eigen: handles non-square constrained systems
  std::chrono::steady_clock::time_point start_;
  long residuals_at_start_ = 0, jacobians_at_start_ = 0;
};

// "x = (0.5, 6.1)" for messages (at most 4 entries shown).
std::string describe_point(const core::Vector& x);

// Throws InputError unless guess (and direction, when non-empty) have num_unknowns entries
// and the problem has at least n - 1 equations for its n unknowns (a curve; `what` names the
// method in the message).
void check_sizes(const core::Problem& problem, const core::Vector& guess,
                 const core::Vector& direction, const char* what);

// Polls hooks.cancel_requested; when it answers true, ends the branch as cancelled (reason and
// message set) and returns true.
bool cancelled(const ContinuationHooks& hooks, Branch& branch);
// The branch ended because it has options.max_points points: sets reason and message.
Branch reached_max_points(Branch branch);

// Step-size rule of both loops: grow after a fast correction, shrink after a slow one, within
// [ds_min, ds_max].
inline double adapted_step(double ds, int newton_iterations, const ContinuationOptions& options) {
  if (newton_iterations <= options.fast_iterations)
    return std::min(ds * options.grow_factor, options.ds_max);
  if (newton_iterations >= options.slow_iterations)
    return std::max(ds * options.shrink_factor, options.ds_min);
  return ds;
}

// The predict-correct step both loops share: attempt(ds, y) predicts into y and corrects it
// with step ds; on failure ds shrinks by options.shrink_factor until a correction converges (and
// hooks.reject_point, given the point as unknowns(y), accepts it) or ds would fall below
// options.ds_min. Every try is reported through hooks.on_attempt.
struct CorrectedStep {
  bool accepted = false;
  double ds = 0;                // the step of the last try
  core::NewtonSummary summary;  // of the last try
  core::NewtonStatus last_failure = core::NewtonStatus::converged;
  std::string last_message;
};

template <class Attempt, class ToUnknowns>  // NewtonSummary attempt(double ds, Vector& y);
                                            // Vector unknowns(const Vector& y)
CorrectedStep correct_with_shrinking(double ds, int index, const ContinuationOptions& options,
                                     const ContinuationHooks& hooks, core::Vector& y,
                                     Attempt&& attempt, ToUnknowns&& unknowns) {
  CorrectedStep r;
  r.ds = ds;
  while (true) {
    r.summary = attempt(r.ds, y);
    r.accepted = r.summary.converged() && y.allFinite();
    std::string rejection;
    if (r.accepted && hooks.reject_point) {
      rejection = hooks.reject_point(unknowns(y));
      r.accepted = rejection.empty();
    }
    if (hooks.on_attempt) hooks.on_attempt({index, r.ds, r.accepted, r.summary, rejection});
    if (r.accepted) return r;
    r.last_failure = r.summary.status;
    r.last_message = rejection.empty() ? r.summary.message : "point rejected: " + rejection;
    const double smaller = r.ds * options.shrink_factor;
    if (smaller < options.ds_min) return r;
    r.ds = smaller;
  }
}

}  // namespace backbone::continuation
