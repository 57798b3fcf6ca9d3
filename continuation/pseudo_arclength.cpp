#include "continuation/pseudo_arclength.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "continuation/branch_points.hpp"
#include "continuation/loop_steps.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/bordered_system.hpp"
#include "core/eigen_newton.hpp"
#include "core/errors.hpp"

namespace backbone::continuation {

core::EvalStatus curve_tangent(const core::Problem& problem, const core::Vector& x,
                               const core::Vector& orientation, double relative_threshold,
                               core::Vector& tangent) {
  core::Matrix J;
  core::EvalStatus s = problem.jacobian(x, J);
  if (s != core::EvalStatus::ok) return s;
  return tangent_from_jacobian(J, orientation, relative_threshold, tangent);
}

core::EvalStatus tangent_from_jacobian(const core::Matrix& J, const core::Vector& orientation,
                                       double relative_threshold, core::Vector& tangent) {
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  core::Matrix bordered(m + 1, n);
  bordered.topRows(m) = J;
  bordered.row(m) = orientation.normalized().transpose();
  core::Vector rhs = core::Vector::Zero(m + 1);
  rhs[m] = 1.0;
  // The minimum-norm solution (core::minimum_norm_solve: a plain QR where the bordered matrix
  // has full rank by a wide margin, else the rank-revealing complete orthogonal decomposition,
  // its threshold relative to the largest pivot, like the rank report's).
  core::minimum_norm_solve(bordered, rhs, relative_threshold, tangent);
  const double norm = tangent.norm();
  if (!std::isfinite(norm) || norm == 0) return core::EvalStatus::non_finite;
  tangent /= norm;
  if (tangent.dot(orientation) < 0) tangent = -tangent;
  return core::EvalStatus::ok;
}

namespace {

StopReason failure_reason(core::NewtonStatus s) {
  return s == core::NewtonStatus::evaluation_failed ? StopReason::evaluation_failed
                                                    : StopReason::step_floor;
}

// The loop proper, in the scaled unknowns z of `problem` (in_scaled_unknowns: the identity view
// when options.scale_unknowns is false). Points are stored in z; the caller converts them. It
// starts from guess (corrected on the hyperplane through it orthogonal to the hint) or, with
// `from`, continues from a saved state (restart.hpp) without correcting or re-deriving anything.
Branch arclength_loop(ScaledProblem& problem, const core::Vector& guess,
                      const core::Vector& hint_in, const LoopState* from, bool record_from,
                      const BranchStart& start, core::Corrector& corrector,
                      const ContinuationOptions& options, const ContinuationHooks& hooks) {
  const double threshold = options.rank.relative_threshold;
  LoopSteps steps(problem, corrector, options, hooks, start);
  std::optional<BranchPointDetector> detector;
  if (options.branch_points.detect) {
    detector.emplace(problem, options, hooks, corrector);
    steps.add_pending_branch_points([&detector] { return detector->finish(); });
  }
  core::Vector x, tangent, previous;
  core::Matrix J;
  // Chord corrections (options.chord_corrections): the base's Jacobian at x, which the next
  // correction starts from (in the units of x), and where (the problem's unknowns) it was
  // computed; empty when the next correction does not try it. The same point's Jacobian, not a
  // new one: ScaledProblem keeps the base's Jacobian per point.
  core::Matrix nearby_base;
  core::Vector nearby_at;
  // Corrections since the last whose chord steps on the nearby Jacobian helped: after two
  // misses the chord is tried only every eighth point. Measured on the contact bar's mode 1
  // below E = 5e-3: the tangent predictor's residual is 2e-2 to 0.5 and a chord step on J(x_k)
  // does not reduce it even at ds = 0.02 (the contact structure moves the Jacobian), so each
  // try costs a factorization and a residual for nothing; at high energy it pays.
  int chord_misses = 0;
  // Keeps the base's Jacobian at `at` (a copy right after J was computed there) when the next
  // correction tries the chord.
  const auto keep_base = [&](core::Vector at) {
    nearby_at.resize(0);
    nearby_base.resize(0, 0);
    const bool tried =
        options.chord_corrections && at.size() > 0 && (chord_misses < 2 || chord_misses % 8 == 0);
    if (!tried) return;
    if (problem.base_jacobian(at, nearby_base) == core::EvalStatus::ok)
      nearby_at = std::move(at);
    else
      nearby_base.resize(0, 0);
  };
  double ds = options.ds;
  // Units that follow the point (scaled_problem.hpp, LocalScale): after each point the units
  // are those of that point, factor = local_factor_at(x). The first point (or a resumed one)
  // is recorded in the unit scale; every saved state is in the unit scale (z, tangent and
  // previous multiplied by the factor they were computed with), and the next step's vectors
  // are derived from it by the same operations in a resumed run, so a restart continues bit
  // for bit. The branch-point detector keeps its samples in the unit scale (branch_points.hpp).
  const bool follow_scale = problem.has_local_scale();
  core::Vector factor = core::Vector::Ones(problem.num_unknowns());
  const auto in_unit_scale = [&](const core::Vector& v) {
    return follow_scale && v.size() > 0 ? core::Vector(v.cwiseProduct(factor)) : v;
  };
  // x, tangent and previous from a state in the unit scale, in the units of its point.
  const auto adopt_units_of = [&](const LoopState& state) {
    x = state.z;
    tangent = state.tangent;
    previous = state.previous;
    if (!follow_scale) return;
    const core::Vector at = state.z.cwiseProduct(problem.unit_scale());
    factor = problem.local_factor_at(at);
    problem.set_factor(factor, problem.local_residual_factor_at(at));
    x = state.z.cwiseQuotient(factor);
    tangent = state.tangent.cwiseQuotient(factor).normalized();
    if (previous.size() > 0) previous = state.previous.cwiseQuotient(factor);
  };
  if (from) {
    steps.resume(*from, record_from);
    adopt_units_of(*from);
    ds = from->ds;
    chord_misses = from->chord_misses;
    keep_base(from->jacobian_point);
    if (detector) {
      // The detector is restored as it was before the saved point was added, then the point is
      // added again from its Jacobian (the same bits: the same z). That locates again what
      // adding it had located in the earlier run: the candidates bracketed by the saved samples
      // (at most the last two) and the point, so with after_point >= index - samples. Those
      // rows of the earlier run are replaced by these, the ones before stand (an interrupted
      // run may have stopped before writing them).
      detector->restore(from->samples, from->jacobian_scale);
      steps.branch_points_from(from->index -
                               static_cast<int>(std::min<std::size_t>(from->samples.size(), 2)));
      if (problem.jacobian(x, J) != core::EvalStatus::ok)
        return steps.end(StopReason::evaluation_failed,
                         fmt::format("the Jacobian could not be evaluated at the saved point {} "
                                     "({})",
                                     from->index, steps.describe(x)));
      detector->add(from->index, x, tangent, J, from->arclength);
      for (BranchPointReport& report : detector->take()) steps.add_branch_point(std::move(report));
    }
  } else {
    // One bordered system for every correction: F plus the arclength row, moved at each step.
    // The first point is the guess corrected on the hyperplane through it orthogonal to the hint.
    core::Vector hint = hint_in.normalized();
    x = guess;
    // In the guess's own units when they follow the point and are not the unit scale there: a
    // guess far above the unit (a saved point corrected again to continue a finished branch)
    // cannot be corrected to the loop's tolerance in the unit scale, whose residual round-off
    // grows with the amplitude (measured: mode 1 of the contact bar at 200 intervals, E = 1e-2,
    // stalled at |F| = 4e-10 against the tolerance 1e-10; its points had converged in their
    // own units, where F is divided by ~100).
    if (follow_scale) {
      const core::Vector at = problem.to_unknowns(guess);
      const core::Vector f = problem.local_factor_at(at);
      if ((f.array() != 1.0).any()) {
        factor = f;
        problem.set_factor(factor, problem.local_residual_factor_at(at));
        x = guess.cwiseQuotient(factor);
        hint = hint.cwiseQuotient(factor).normalized();
      }
    }
    core::BorderedSystem first(problem, {core::BorderRow::linear(hint, x, 0.0, "arclength")});
    if (!steps.start(first, x, "")) return steps.take();
    if (problem.jacobian(x, J) != core::EvalStatus::ok ||
        tangent_from_jacobian(J, hint, threshold, tangent) != core::EvalStatus::ok) {
      steps.report_first(nullptr);
      return steps.end(StopReason::evaluation_failed,
                       fmt::format("the Jacobian could not be evaluated at point {} ({})",
                                   start.index, steps.describe(x)));
    }
    if (options.start_along_direction) tangent = hint;
    keep_base(problem.to_unknowns(x));
    auto state = std::make_shared<LoopState>();
    state->method = Method::arclength;
    state->z = in_unit_scale(x);
    state->tangent = in_unit_scale(tangent);
    state->ds = ds;
    state->jacobian_point = nearby_at;
    const std::shared_ptr<const LoopState> first_state = state;
    steps.report_first(std::move(state));
    if (detector) {
      detector->add(start.index, x, tangent, J, start.arclength);
      for (BranchPointReport& report : detector->take()) steps.add_branch_point(std::move(report));
    }
    adopt_units_of(*first_state);
  }
  core::BorderedSystem system(problem, {core::BorderRow::linear(tangent, x, 0.0, "arclength")});
  // Passing an attached family: a correction that turns away from the predictor direction by
  // more than max_turn_degrees landed on another family (or jumped a fold); it is refused, and
  // ds shrinks, so the branch keeps the direction closest to the incoming one.
  const double max_turn = options.branch_points.max_turn_degrees;

  while (steps.begin_step()) {
    const int index = steps.next_index();
    // Predictor direction: the secant through the last two points, or the tangent.
    core::Vector step_direction = tangent;
    if (options.predictor == Predictor::secant && previous.size() > 0) {
      core::Vector secant = x - previous;
      if (secant.norm() > 0) step_direction = secant.normalized();
    }
    // Quadratic: the chord from the previous point p to x is s t - (s^2 / 2) k + O(s^3) for the
    // curvature vector k (orthogonal to t), so k ~ 2 (s t - (x - p)) / s^2, and the predictor
    // x + ds t + (ds^2 / 2) k lands O(ds^3) from the curve instead of O(ds^2). Only while the
    // bend it adds is below a quarter of the step (else the curve turns too fast for the
    // estimate to hold, as at a branch point) and below 30 degrees between the chord and t.
    core::Vector bend;
    if (options.predictor == Predictor::quadratic && previous.size() == x.size()) {
      const core::Vector chord = x - previous;
      const double s = chord.norm();
      if (s > 0 && chord.dot(tangent) > std::cos(std::numbers::pi / 6) * s) {
        bend = 2 * (s * tangent - chord) / (s * s);
        bend -= tangent * tangent.dot(bend);
      }
    }
    system.set_anchor(0, x);
    system.set_direction(0, step_direction);
    core::Matrix bordered_nearby;
    if (nearby_base.size() > 0 &&
        system.jacobian_with_base(x, problem.in_current_units(nearby_base), bordered_nearby) !=
            core::EvalStatus::ok)
      bordered_nearby.resize(0, 0);
    core::Vector y;
    const CorrectedStep corrected = steps.correct(
        ds, y,
        [&](double ds_try, core::Vector& predicted) {
          predicted = x + ds_try * step_direction;
          if (bend.size() > 0 && 0.5 * ds_try * bend.norm() <= 0.25)
            predicted += 0.5 * ds_try * ds_try * bend;
          system.set_value(0, ds_try);
          return bordered_nearby.size() > 0 ? corrector.solve(system, predicted, bordered_nearby)
                                            : corrector.solve(system, predicted);
        },
        [&](const core::Vector& corrected_point) {
          if (max_turn <= 0) return std::string();
          const core::Vector secant = corrected_point - x;
          const double norm = secant.norm();
          if (!(norm > 0)) return std::string();
          const double turn = std::acos(std::clamp(secant.dot(step_direction) / norm, -1.0, 1.0)) *
                              180 / std::numbers::pi;
          if (turn <= max_turn) return std::string();
          return fmt::format(
              "the step turned by {:.1f} degrees from the predictor direction "
              "(max_turn_degrees {:g})",
              turn, max_turn);
        });
    ds = corrected.ds;
    if (!corrected.accepted)
      return steps.end(
          failure_reason(corrected.last_failure),
          fmt::format("no point {} could be corrected with ds >= ds_min = {:.3g} from {} (last "
                      "Newton status {}: {})",
                      index, options.ds_min, steps.describe(x),
                      core::to_string(corrected.last_failure), corrected.last_message));
    const int iterations = corrected.summary.iterations;
    chord_misses =
        bordered_nearby.size() > 0 && corrected.summary.chord_steps > 0 ? 0 : chord_misses + 1;
    core::Vector next_tangent;
    core::EvalStatus tangent_status = problem.jacobian(y, J);
    keep_base(tangent_status == core::EvalStatus::ok ? problem.to_unknowns(y) : core::Vector());
    if (tangent_status == core::EvalStatus::ok)
      tangent_status = tangent_from_jacobian(J, step_direction, threshold, next_tangent);
    // A tangent that turns from the accepted chord x -> y by more than max_turn_degrees
    // contradicts the step just accepted (its secant passed the same check): it is the
    // finite-difference Jacobian's, not the curve's. Measured on the contact bar's mode 1 at
    // 1.3e5 g0: forward differences across a kink of the contact map (7e-5 relative in four
    // columns, against a smallest kept singular value of 7e-6) turned it by 52.8 degrees, and
    // every retry turned as much. The chord keeps the incoming direction, as passing a branch
    // point does. Only in units that follow the point: in a family of more dimensions (a
    // followed branch, follow.hpp) the projected tangent may turn from the chord by design.
    if (follow_scale && tangent_status == core::EvalStatus::ok && max_turn > 0) {
      const core::Vector chord = y - x;
      const double norm = chord.norm();
      if (norm > 0 && std::acos(std::clamp(next_tangent.dot(chord) / norm, -1.0, 1.0)) * 180 /
                              std::numbers::pi >
                          max_turn)
        next_tangent = chord / norm;
    }
    const bool last = index + 1 == options.max_points || tangent_status != core::EvalStatus::ok;
    // The state the next step starts from (saved with the point for a restart).
    std::shared_ptr<LoopState> state;
    if (tangent_status == core::EvalStatus::ok) {
      state = std::make_shared<LoopState>();
      state->method = Method::arclength;
      state->z = in_unit_scale(y);
      state->tangent = in_unit_scale(next_tangent);
      if (options.predictor != Predictor::tangent) state->previous = in_unit_scale(x);
      state->jacobian_point = nearby_at;
      state->chord_misses = chord_misses;
      state->ds = adapted_step(ds, corrected.summary.equivalent_iterations(), options);
      if (detector) {
        state->samples = detector->samples();
        state->jacobian_scale = detector->jacobian_scale();
      }
    }
    if (!steps.record(x, y, step_direction, iterations, ds, last, state,
                      tangent_status == core::EvalStatus::ok ? &next_tangent : nullptr))
      return steps.take();
    if (tangent_status != core::EvalStatus::ok)
      return steps.end(StopReason::evaluation_failed,
                       fmt::format("the Jacobian could not be evaluated at point {} ({}: {})",
                                   index, core::to_string(tangent_status), steps.describe(y)));
    if (detector) {
      detector->add(index, y, next_tangent, J, steps.arclength());
      for (BranchPointReport& report : detector->take()) steps.add_branch_point(std::move(report));
    }
    ds = state->ds;
    if (follow_scale) {
      adopt_units_of(*state);
      continue;
    }
    if (options.predictor != Predictor::tangent) previous = x;
    x = y;
    tangent = next_tangent;
  }
  return steps.take();
}

}  // namespace

Branch pseudo_arclength(const core::Problem& problem, const core::Vector& guess,
                        const core::Vector& direction, core::Corrector& corrector,
                        const ContinuationOptions& options, const ContinuationHooks& hooks,
                        const BranchStart& start) {
  options.validate();
  check_sizes(problem, guess, direction, "pseudo-arclength follows curves");
  const int n = problem.num_unknowns();
  const core::Vector hint = direction.size() ? direction : core::Vector::Unit(n, n - 1);
  if (!(hint.norm() > 0) || !hint.allFinite())
    throw core::InputError("direction", "must be a finite non-zero vector");

  return in_scaled_unknowns(
      problem, options, hooks, [&](ScaledProblem& scaled, const ContinuationHooks& inner) {
        return arclength_loop(scaled, scaled.to_scaled(guess), scaled.to_scaled(hint), nullptr,
                              false, start, corrector, options, inner);
      });
}

Branch pseudo_arclength(const core::Problem& problem, const LoopState& from, bool record_from,
                        core::Corrector& corrector, const ContinuationOptions& options,
                        const ContinuationHooks& hooks) {
  options.validate();
  check_sizes(problem, from.z, from.tangent, "pseudo-arclength follows curves");
  if (const std::string why = state_mismatch(from, problem, options, Method::arclength);
      !why.empty())
    throw core::InputError("state", why);
  return in_scaled_unknowns(problem, options, hooks,
                            [&](ScaledProblem& scaled, const ContinuationHooks& inner) {
                              return arclength_loop(scaled, from.z, from.tangent, &from,
                                                    record_from, {}, corrector, options, inner);
                            });
}

}  // namespace backbone::continuation
