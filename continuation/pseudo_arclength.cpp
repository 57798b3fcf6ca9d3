#include "continuation/pseudo_arclength.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <cmath>

#include "continuation/natural.hpp"
#include "continuation/point_recorder.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"

namespace backbone::continuation {

ArclengthSystem::ArclengthSystem(const core::Problem& base, core::Vector anchor,
                                 core::Vector tangent, double ds)
    : base_(base), anchor_(std::move(anchor)), tangent_(std::move(tangent)), ds_(ds) {}

core::EvalStatus ArclengthSystem::compute_residual(const core::Vector& x, core::Vector& r) const {
  core::Vector f;
  core::EvalStatus s = base_.residual(x, f);
  if (s != core::EvalStatus::ok) return s;
  const int m = base_.num_equations();
  r.resize(m + 1);
  r.head(m) = f;
  r[m] = tangent_.dot(x - anchor_) - ds_;
  return core::EvalStatus::ok;
}

core::EvalStatus ArclengthSystem::compute_jacobian(const core::Vector& x, core::Matrix& J) const {
  core::Matrix Jf;
  core::EvalStatus s = base_.jacobian(x, Jf);
  if (s != core::EvalStatus::ok) return s;
  const int m = base_.num_equations();
  J.resize(m + 1, base_.num_unknowns());
  J.topRows(m) = Jf;
  J.row(m) = tangent_.transpose();
  return core::EvalStatus::ok;
}

core::EvalStatus curve_tangent(const core::Problem& problem, const core::Vector& x,
                               const core::Vector& orientation, double relative_threshold,
                               core::Vector& tangent) {
  core::Matrix J;
  core::EvalStatus s = problem.jacobian(x, J);
  if (s != core::EvalStatus::ok) return s;
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  core::Matrix bordered(m + 1, n);
  bordered.topRows(m) = J;
  bordered.row(m) = orientation.normalized().transpose();
  core::Vector rhs = core::Vector::Zero(m + 1);
  rhs[m] = 1.0;
  // Complete orthogonal decomposition: rank-revealing, minimum-norm solution. The threshold is
  // relative to the largest pivot, like the rank report's.
  Eigen::CompleteOrthogonalDecomposition<core::Matrix> cod;
  cod.setThreshold(relative_threshold);
  cod.compute(bordered);
  tangent = cod.solve(rhs);
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

// The loop proper, in the scaled unknowns z of `problem` (a ScaledProblem view: the identity
// when options.scale_unknowns is false). Points are stored in z; the caller converts them.
Branch arclength_loop(const ScaledProblem& problem, const core::Vector& guess,
                      const core::Vector& hint_in, core::Corrector& corrector,
                      const ContinuationOptions& options, const ContinuationHooks& hooks) {
  const core::Vector hint = hint_in.normalized();
  const auto unknowns = [&](const core::Vector& z) { return problem.to_unknowns(z); };
  const auto describe = [&](const core::Vector& z) { return describe_point(unknowns(z)); };
  const auto rejection_of = [&](const core::Vector& z) {
    return hooks.reject_point ? hooks.reject_point(unknowns(z)) : std::string();
  };

  Branch branch;
  PointRecorder recorder(problem, options, &problem.base());
  const double threshold = options.rank.relative_threshold;

  // First point: the guess corrected on the hyperplane through it orthogonal to the hint.
  recorder.begin();
  core::Vector x = guess;
  {
    ArclengthSystem first(problem, guess, hint, 0.0);
    core::NewtonSummary s = corrector.solve(first, x);
    const std::string rejection = s.converged() ? rejection_of(x) : std::string();
    if (hooks.on_attempt)
      hooks.on_attempt({0, 0.0, s.converged() && rejection.empty(), s, rejection});
    if (!s.converged()) {
      branch.reason = s.status == core::NewtonStatus::evaluation_failed
                          ? StopReason::evaluation_failed
                          : StopReason::newton_failed;
      branch.message = fmt::format("the starting guess did not converge ({}; {}): {}",
                                   core::to_string(s.status), describe(guess), s.message);
      return branch;
    }
    if (!rejection.empty()) {
      branch.reason = StopReason::newton_failed;
      branch.message = fmt::format(
          "the starting guess converged to a point the check rejects "
          "({}): {}",
          describe(x), rejection);
      return branch;
    }
    branch.points.push_back(recorder.finish(x, 0, s.iterations, 0.0, 0.0, true));
    if (hooks.on_point) hooks.on_point(branch.points.back());
  }
  core::Vector tangent;
  if (curve_tangent(problem, x, hint, threshold, tangent) != core::EvalStatus::ok) {
    branch.reason = StopReason::evaluation_failed;
    branch.message =
        fmt::format("the Jacobian could not be evaluated at point 0 ({})", describe(x));
    return branch;
  }

  double ds = options.ds;
  double arclength = 0;
  core::Vector previous = x;
  bool have_previous = false;
  while (static_cast<int>(branch.points.size()) < options.max_points) {
    if (cancelled(hooks, branch)) return branch;
    const int index = static_cast<int>(branch.points.size());
    recorder.begin();
    // Predictor direction: the secant through the last two points, or the tangent.
    core::Vector step_direction = tangent;
    if (options.predictor == Predictor::secant && have_previous) {
      core::Vector secant = x - previous;
      if (secant.norm() > 0) step_direction = secant.normalized();
    }
    core::Vector y;
    const CorrectedStep corrected = correct_with_shrinking(
        ds, index, options, hooks, y,
        [&](double ds_try, core::Vector& predicted) {
          predicted = x + ds_try * step_direction;
          const ArclengthSystem system(problem, x, step_direction, ds_try);
          return corrector.solve(system, predicted);
        },
        unknowns);
    ds = corrected.ds;
    const core::NewtonSummary& s = corrected.summary;
    const core::NewtonStatus last_failure = corrected.last_failure;
    const std::string& last_message = corrected.last_message;
    if (!corrected.accepted) {
      branch.reason = failure_reason(last_failure);
      branch.message = fmt::format(
          "no point {} could be corrected with ds >= ds_min = {:.3g} from {} (last Newton "
          "status {}: {})",
          index, options.ds_min, describe(x), core::to_string(last_failure), last_message);
      return branch;
    }
    core::Vector next_tangent;
    const core::EvalStatus tangent_status =
        curve_tangent(problem, y, step_direction, threshold, next_tangent);
    arclength += (y - x).norm();
    const bool last = index + 1 == options.max_points || tangent_status != core::EvalStatus::ok;
    BranchPoint point = recorder.finish(y, index, s.iterations, ds, arclength, last);

    double bound_value = 0;
    if (const Bound* bound = recorder.violated_bound(point, bound_value)) {
      // Land on the bound: correct [F; observable - bound] from the crossing point.
      branch.reason = StopReason::bound_reached;
      branch.message = fmt::format("{} reached its bound {:.6g} after point {}", bound->observable,
                                   bound_value, index - 1);
      if (options.land_on_bounds) {
        recorder.begin();
        NaturalParameter p = NaturalParameter::of_observable(bound->observable);
        ParameterConstraintSystem on_bound(problem, p, bound_value);
        // From the crossing point first, then from the last point inside the bound.
        core::Vector z = y;
        core::NewtonSummary sb = corrector.solve(on_bound, z);
        if (hooks.on_attempt) hooks.on_attempt({index, ds, sb.converged(), sb, {}});
        if (!sb.converged()) {
          z = x;
          sb = corrector.solve(on_bound, z);
          if (hooks.on_attempt) hooks.on_attempt({index, ds, sb.converged(), sb, {}});
        }
        if (sb.converged() && (z - x).dot(step_direction) > 0 && rejection_of(z).empty()) {
          arclength += (z - x).norm() - (y - x).norm();
          branch.points.push_back(
              recorder.finish(z, index, sb.iterations, (z - x).norm(), arclength, true));
          if (hooks.on_point) hooks.on_point(branch.points.back());
          branch.message = fmt::format("{} reached its bound {:.6g} (point {} lies on it)",
                                       bound->observable, bound_value, index);
        }
      }
      return branch;
    }
    branch.points.push_back(std::move(point));
    if (hooks.on_point) hooks.on_point(branch.points.back());
    if (tangent_status != core::EvalStatus::ok) {
      branch.reason = StopReason::evaluation_failed;
      branch.message = fmt::format("the Jacobian could not be evaluated at point {} ({}: {})",
                                   index, core::to_string(tangent_status), describe(y));
      return branch;
    }
    previous = x;
    have_previous = true;
    x = y;
    tangent = next_tangent;
    ds = adapted_step(ds, s.iterations, options);
  }
  return reached_max_points(std::move(branch));
}

}  // namespace

Branch pseudo_arclength(const core::Problem& problem, const core::Vector& guess,
                        const core::Vector& direction, core::Corrector& corrector,
                        const ContinuationOptions& options, const ContinuationHooks& hooks) {
  options.validate();
  check_sizes(problem, guess, direction, "pseudo-arclength follows curves");
  const int n = problem.num_unknowns();
  const core::Vector hint = direction.size() ? direction : core::Vector::Unit(n, n - 1);
  if (!(hint.norm() > 0) || !hint.allFinite())
    throw core::InputError("direction", "must be a finite non-zero vector");

  const ScaledProblem scaled = options.scale_unknowns
                                   ? ScaledProblem(problem)
                                   : ScaledProblem(problem, core::Vector::Ones(n));
  ContinuationHooks inner = hooks;
  if (hooks.on_point)
    inner.on_point = [&](const BranchPoint& p) {
      BranchPoint q = p;
      q.x = scaled.to_unknowns(p.x);
      hooks.on_point(q);
    };
  Branch branch = arclength_loop(scaled, scaled.to_scaled(guess), scaled.to_scaled(hint), corrector,
                                 options, inner);
  for (BranchPoint& p : branch.points) p.x = scaled.to_unknowns(p.x);
  return branch;
}

}  // namespace backbone::continuation
