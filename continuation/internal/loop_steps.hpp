// Internal to backbone::continuation: the steps natural and pseudo-arclength continuation share.
//
// The two loops differ only in their predictor and in the row that borders F (the arclength
// row t . (x - x_k) - ds, or the parameter row p(x) - lambda: core/solvers/bordered_system.hpp).
// The rest is said once, here:
//   - in_scaled_unknowns runs a loop in z = x ./ typical_scale() (options.scale_unknowns,
//     scaled_problem.hpp) and hands points and hooks.reject_point back in the problem's unknowns,
//     so ds, the step_size column and the arclength column are dimensionless in both loops;
//   - LoopSteps::start corrects the first point and asks hooks.reject_point about it;
//   - LoopSteps::correct is the predict-correct step with the shrinking rule and the rejection
//     hook (correct_with_shrinking);
//   - LoopSteps::record adds the chord |y - x| in z to the arclength, records the point with the
//     loop's state after it (restart.hpp: what the next step needs, saved for a restart), and
//     when it crossed a bound lands on the bound (F plus the row observable - bound value,
//     corrected from the crossing point, then from the last point inside) and ends the branch;
//   - LoopSteps::resume takes a saved LoopState up instead of start: the loop then continues
//     from the state's point as the run that saved it would have.
//
//   return in_scaled_unknowns(problem, options, hooks, [&](const ScaledProblem& scaled,
//                                                          const ContinuationHooks& inner) {
//     LoopSteps steps(scaled, corrector, options, inner);
//     core::Vector x = scaled.to_scaled(guess);
//     if (!steps.start(first_system, x, "")) return steps.take();
//     while (steps.begin_step()) {
//       core::Vector y;
//       const CorrectedStep c = steps.correct(ds, y, attempt);   // attempt(ds, y) -> summary
//       if (!c.accepted) return steps.end(StopReason::step_floor, "...");
//       if (!steps.record(x, y, forward, c.summary.iterations, c.ds, false, state_after(y)))
//         return steps.take();
//       x = y;
//     }
//     return steps.take();
//   });
#pragma once

#include <algorithm>
#include <functional>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/internal/point_recorder.hpp"
#include "continuation/options.hpp"
#include "continuation/restart.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation {

// "x = (0.5, 6.1)" for messages (at most 4 entries shown).
std::string describe_point(const core::Vector& x);

// Throws InputError unless guess (and direction, when non-empty) have num_unknowns entries
// and the problem has at least n - 1 equations for its n unknowns (a curve; `what` names the
// method in the message).
void check_sizes(const core::Problem& problem, const core::Vector& guess,
                 const core::Vector& direction, const char* what);

// The unit scale of the loops' ScaledProblem: typical_scale() with options.scale_unknowns, else
// ones.
inline core::Vector loop_unit_scale(const core::Problem& problem,
                                    const ContinuationOptions& options) {
  return options.scale_unknowns ? core::Vector(problem.typical_scale().cwiseAbs())
                                : core::Vector::Ones(problem.num_unknowns());
}

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
// hooks.reject_point accepts y) or ds would fall below options.ds_min. Every try is reported
// through hooks.on_attempt.
struct CorrectedStep {
  bool accepted = false;
  double ds = 0;                // the step of the last try
  core::NewtonSummary summary;  // of the last try
  core::NewtonStatus last_failure = core::NewtonStatus::converged;
  std::string last_message;
  int rejections = 0;  // converged tries refused by check or hooks.reject_point
};

// check(y), run first on a converged y, is the loop's own test (pseudo-arclength: the turn of
// the step, options.branch_points.max_turn_degrees); a non-empty answer rejects y like
// hooks.reject_point.
template <class Attempt, class Check>  // core::NewtonSummary attempt(double ds, core::Vector& y);
CorrectedStep correct_with_shrinking(double ds, int index, const ContinuationOptions& options,
                                     const ContinuationHooks& hooks, core::Vector& y,
                                     Attempt&& attempt, Check&& check) {
  CorrectedStep r;
  r.ds = ds;
  while (true) {
    r.summary = attempt(r.ds, y);
    r.accepted = r.summary.converged() && y.allFinite();
    std::string rejection;
    if (r.accepted) {
      rejection = check(y);
      r.accepted = rejection.empty();
    }
    if (r.accepted && hooks.reject_point) {
      rejection = hooks.reject_point(y);
      r.accepted = rejection.empty();
    }
    if (!rejection.empty()) ++r.rejections;
    if (hooks.on_attempt) hooks.on_attempt({index, r.ds, r.accepted, r.summary, rejection});
    if (r.accepted) return r;
    r.last_failure = r.summary.status;
    r.last_message = rejection.empty() ? r.summary.message : "point rejected: " + rejection;
    const double smaller = r.ds * options.shrink_factor;
    if (smaller < options.ds_min) return r;
    r.ds = smaller;
  }
}

// Runs loop(scaled, inner) -> Branch on the view of `problem` in scaled unknowns (the identity
// view when options.scale_unknowns is false). inner is `hooks` with on_point and reject_point
// seeing the problem's own unknowns; the returned branch's points are converted back to them.
// A loop may change the units of the view between points (ScaledProblem::set_factor): the
// hooks convert with the units of the moment, LoopSteps::take each point with its own.
template <class Loop>
Branch in_scaled_unknowns(const core::Problem& problem, const ContinuationOptions& options,
                          const ContinuationHooks& hooks, Loop&& loop) {
  ScaledProblem scaled(problem, loop_unit_scale(problem, options));
  ContinuationHooks inner = hooks;
  if (hooks.on_point)
    inner.on_point = [&](const BranchPoint& p) {
      BranchPoint q = p;
      q.x = scaled.to_unknowns(p.x);
      hooks.on_point(q);
    };
  if (hooks.reject_point)
    inner.reject_point = [&](const core::Vector& z) {
      return hooks.reject_point(scaled.to_unknowns(z));
    };
  return loop(scaled, static_cast<const ContinuationHooks&>(inner));
}

// The branch under construction and the steps that add to it. All vectors are in the scaled
// unknowns of `problem`; hooks are the inner hooks of in_scaled_unknowns.
class LoopSteps {
 public:
  LoopSteps(const ScaledProblem& problem, core::Corrector& corrector,
            const ContinuationOptions& options, const ContinuationHooks& hooks,
            const BranchStart& start = {});

  // The first point: corrects `system` (F plus the loop's row) from z in place, asks
  // hooks.reject_point and records it (index and arclength of the BranchStart). False when it
  // fails (the branch's reason and message set); `where` adds context after "the starting guess
  // did not converge". The loop then reports it with report_first, with its state when it has
  // one.
  bool start(const core::Problem& system, core::Vector& z, const std::string& where);
  // The first point's null directions are then verified by the next recorded point, a known
  // neighbour, instead of probes of their own (or by probes when the branch ends first); the
  // point is reported just before that next one. For a loop whose first step leaves along the
  // first point's tangent.
  void verify_first_by_next() { defer_first_ = true; }
  void report_first(std::shared_ptr<LoopState> state);
  // Verifies and reports a deferred first point now, by probes (nothing when none waits): before
  // the loop leaves the units it was recorded in (its verification runs in those).
  void verify_first_now() { flush_first(nullptr); }

  // In place of start: continues from a saved state (its index and arclength). record: the
  // state's point becomes the branch's first point (recorded, not corrected: --start), else the
  // branch begins with the next one (--resume). InputError when the state does not fit the
  // problem (restart.hpp: state_mismatch).
  void resume(const LoopState& state, bool record);
  // After resume without recording: the saved point x (in the loop's units) is the next point's
  // known neighbour, its residual evaluated here as finish() did when it was recorded, so that
  // the next point's rank verification (and its evaluation counts) are the uninterrupted run's.
  void remember_saved_point(const core::Vector& x) { recorder_.remember(x); }
  int switch_index() const { return switch_index_; }

  // Before each further step: false when the branch has options.max_points points or a cancel
  // was requested (reason and message set); else starts measuring the point's cost.
  bool begin_step();
  int next_index() const { return first_index_ + static_cast<int>(branch_.points.size()); }

  template <class Attempt>
  CorrectedStep correct(double ds, core::Vector& y, Attempt&& attempt) {
    return correct(ds, y, std::forward<Attempt>(attempt),
                   [](const core::Vector&) { return std::string(); });
  }
  template <class Attempt, class Check>
  CorrectedStep correct(double ds, core::Vector& y, Attempt&& attempt, Check&& check) {
    CorrectedStep r =
        correct_with_shrinking(ds, next_index(), options_, hooks_, y,
                               std::forward<Attempt>(attempt), std::forward<Check>(check));
    rejected_ += r.rejections;
    return r;
  }

  // Arclength of the last recorded point.
  double arclength() const { return arclength_; }
  // Adds a located candidate to the branch and reports it (hooks.on_branch_point).
  void add_branch_point(BranchPointReport report);
  // Candidates still being located when the branch ends (the detector's worker): take() adds
  // what this returns (it waits for them) before it hands the branch over.
  void add_pending_branch_points(std::function<std::vector<BranchPointReport>(int*)> pending) {
    pending_branch_points_ = std::move(pending);
  }
  // The detector's count of brackets located or given up (hooks.on_brackets_settled when it
  // grows).
  void brackets_settled(int settled);
  // A resumed run locates again from this after_point on (Branch::branch_points_from).
  void branch_points_from(int after_point) { branch_.branch_points_from = after_point; }

  // Records y, corrected from the last point x with step ds: the arclength grows by |y - x|.
  // state: the loop's state after y (its index, arclength, scale and switch index are filled
  // here), null when the loop cannot go on from y. When y leaves a bound the branch ends
  // (false): with options.land_on_bounds, F plus the bound's observable row is corrected from y,
  // then from x, and the solution is recorded in y's place (without a state) if it lies ahead of
  // x along `forward` and hooks.reject_point accepts it.
  // curve_direction: the curve's direction at y for a dimension re-check, in the units of y
  // (null: the state's tangent, else y - x).
  bool record(const core::Vector& x, const core::Vector& y, const core::Vector& forward,
              int newton_iterations, double ds, bool force_rank, std::shared_ptr<LoopState> state,
              const core::Vector* curve_direction = nullptr);

  // The bound whose observable, extrapolated along the chord of the last two points (recorded,
  // or before a resume: the state's known points), reaches it within ds of the last point
  // (null: none, or fewer than two points): its value
  // and the distance to it. The loop then aims its step at the bound (land_ahead) instead of
  // crossing it and landing back.
  const Bound* bound_within(double ds, double& value, double& ds_to_bound) const;
  // F plus the bound's observable row corrected from `predicted`, a point ds ahead of the last
  // point x: true, with the branch ended (bound_reached) and the solution recorded, when it
  // converges ahead of x along `forward` and hooks.reject_point accepts it; false, with nothing
  // recorded, otherwise (the loop then steps as usual).
  bool land_ahead(const Bound& bound, double value, const core::Vector& x,
                  const core::Vector& predicted, const core::Vector& forward, double ds) {
    return land(bound, value, {&predicted}, x, forward, ds, arclength_);
  }

  // Ends the branch: sets reason and message, returns the branch.
  Branch end(StopReason reason, std::string message);
  // The branch, each point converted to the problem's unknowns with the units it was
  // recorded in.
  Branch take();

  // describe_point of z in the problem's unknowns.
  std::string describe(const core::Vector& z) const;

 private:
  // Verifies and reports the first point when its verification was deferred (neighbour: the
  // point recorded last, or null for probes).
  void flush_first(const core::Vector* neighbour);
  void push(BranchPoint point);
  void push_back(BranchPoint point);  // adds without reporting
  void attach(BranchPoint& point, std::shared_ptr<LoopState> state) const;
  std::string rejection_of(const core::Vector& z) const;
  bool land(const Bound& bound, double value, std::initializer_list<const core::Vector*> starts,
            const core::Vector& x, const core::Vector& forward, double ds, double arclength_at_x);
  void land_on_bound(const Bound& bound, double value, const core::Vector& x, const core::Vector& y,
                     const core::Vector& forward, double ds, double arclength_at_x);

  const ScaledProblem& problem_;
  core::Corrector& corrector_;
  const ContinuationOptions& options_;
  const ContinuationHooks& hooks_;
  PointRecorder recorder_;
  Branch branch_;
  std::vector<KnownPoint> known_points_;    // a resumed state's (LoopState::known_points)
  std::vector<core::Vector> point_scales_;  // problem_.scale() when each point was added
  int first_index_ = 0;
  double arclength_ = 0;
  int switch_index_ = -1;
  int rejected_ = 0;  // Branch::rejected_corrections so far
  bool defer_first_ = false, first_pending_ = false;
  std::size_t first_position_ = 0;
  core::Vector first_direction_;
  std::function<std::vector<BranchPointReport>(int*)> pending_branch_points_;
  int brackets_settled_ = -1;
};

}  // namespace backbone::continuation
