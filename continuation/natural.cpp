#include "continuation/natural.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "continuation/point_recorder.hpp"
#include "continuation/pseudo_arclength.hpp"
#include "core/errors.hpp"

namespace backbone::continuation {

NaturalParameter NaturalParameter::of_unknown(int index, std::string label, double direction) {
  NaturalParameter p;
  p.kind = Kind::unknown;
  p.index = index;
  p.name = std::move(label);
  p.direction = direction;
  return p;
}

NaturalParameter NaturalParameter::of_observable(std::string name, double direction) {
  NaturalParameter p;
  p.kind = Kind::observable;
  p.name = std::move(name);
  p.direction = direction;
  return p;
}

double parameter_value(const core::Problem& problem, const NaturalParameter& parameter,
                       const core::Vector& x) {
  if (parameter.kind == NaturalParameter::Kind::unknown) return x[parameter.index];
  for (const auto& [key, value] : problem.observables(x))
    if (key == parameter.name) return value;
  return std::numeric_limits<double>::quiet_NaN();
}

ParameterConstraintSystem::ParameterConstraintSystem(const core::Problem& base,
                                                     NaturalParameter parameter, double value)
    : base_(base), parameter_(std::move(parameter)), value_(value) {}

double ParameterConstraintSystem::row_scale() const {
  if (parameter_.kind == NaturalParameter::Kind::unknown) return 1.0;
  const double size = std::abs(value_);
  return size > 0 && std::isfinite(size) ? size : 1.0;
}

core::EvalStatus ParameterConstraintSystem::compute_residual(const core::Vector& x,
                                                             core::Vector& r) const {
  core::Vector f;
  core::EvalStatus s = base_.residual(x, f);
  if (s != core::EvalStatus::ok) return s;
  const int m = base_.num_equations();
  r.resize(m + 1);
  r.head(m) = f;
  r[m] = (parameter_value(base_, parameter_, x) - value_) / row_scale();
  return std::isfinite(r[m]) ? core::EvalStatus::ok : core::EvalStatus::failed;
}

core::EvalStatus ParameterConstraintSystem::compute_jacobian(const core::Vector& x,
                                                             core::Matrix& J) const {
  core::Matrix Jf;
  core::EvalStatus s = base_.jacobian(x, Jf);
  if (s != core::EvalStatus::ok) return s;
  const int m = base_.num_equations();
  const int n = base_.num_unknowns();
  J.resize(m + 1, n);
  J.topRows(m) = Jf;
  if (parameter_.kind == NaturalParameter::Kind::unknown) {
    J.row(m).setZero();
    J(m, parameter_.index) = 1.0;
    return core::EvalStatus::ok;
  }
  // Central differences of a closed-form observable: step cbrt(eps) * max(|x_j|, scale_j).
  const core::Vector scale = base_.typical_scale();
  for (int j = 0; j < n; ++j) {
    const double h = 6e-6 * std::max(std::abs(x[j]), scale[j]);
    core::Vector xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    J(m, j) = (parameter_value(base_, parameter_, xp) - parameter_value(base_, parameter_, xm)) /
              ((xp[j] - xm[j]) * row_scale());
  }
  return J.row(m).allFinite() ? core::EvalStatus::ok : core::EvalStatus::non_finite;
}

Branch natural(const core::Problem& problem, const core::Vector& guess,
               const NaturalParameter& parameter, core::Corrector& corrector,
               const ContinuationOptions& options, const ContinuationHooks& hooks) {
  options.validate();
  check_sizes(problem, guess, core::Vector(), "natural continuation in one parameter");
  const int n = problem.num_unknowns();
  if (parameter.kind == NaturalParameter::Kind::unknown &&
      (parameter.index < 0 || parameter.index >= n))
    throw core::InputError("natural_parameter", fmt::format("unknown index {} out of range [0, {})",
                                                            parameter.index, n));
  if (!(parameter.direction == 1.0 || parameter.direction == -1.0))
    throw core::InputError("natural_direction",
                           fmt::format("must be +1 or -1 (got {})", parameter.direction));
  const double lambda0 = parameter_value(problem, parameter, guess);
  if (!std::isfinite(lambda0))
    throw core::InputError(
        "natural_parameter",
        fmt::format("the problem reports no finite observable '{}' at the guess", parameter.name));

  // ds is dimensionless like pseudo-arclength's when the parameter is an unknown and unknowns
  // are scaled: a step of ds moves it by ds * typical_scale. An observable steps in its units.
  const double unit = options.scale_unknowns && parameter.kind == NaturalParameter::Kind::unknown
                          ? std::abs(problem.typical_scale()[parameter.index])
                          : 1.0;
  if (!(unit > 0) || !std::isfinite(unit))
    throw core::InputError("typical_scale", fmt::format("entry {} must be finite and > 0 (got {})",
                                                        parameter.index, unit));

  Branch branch;
  PointRecorder recorder(problem, options);
  ParameterConstraintSystem system(problem, parameter, lambda0);

  recorder.begin();
  core::Vector x = guess;
  core::NewtonSummary s = corrector.solve(system, x);
  if (hooks.on_attempt) hooks.on_attempt({0, 0.0, s.converged(), s, {}});
  if (!s.converged()) {
    branch.reason = s.status == core::NewtonStatus::evaluation_failed
                        ? StopReason::evaluation_failed
                        : StopReason::newton_failed;
    branch.message = fmt::format("the starting guess did not converge at {} = {:.10g} ({}; {}): {}",
                                 parameter.name, lambda0, core::to_string(s.status),
                                 describe_point(guess), s.message);
    return branch;
  }
  double arclength = 0;
  branch.points.push_back(recorder.finish(x, 0, s.iterations, 0.0, 0.0, true));
  if (hooks.on_point) hooks.on_point(branch.points.back());

  double lambda = lambda0;
  double ds = options.ds;
  core::Vector previous = x;
  double previous_step = 0;
  while (static_cast<int>(branch.points.size()) < options.max_points) {
    if (cancelled(hooks, branch)) return branch;
    const int index = static_cast<int>(branch.points.size());
    recorder.begin();
    // dx/dlambda for the predictor: tangent of the curve scaled so that dp = 1, or the secant.
    core::Vector rate = core::Vector::Zero(n);
    if (options.predictor == Predictor::secant && previous_step != 0) {
      rate = (x - previous) / previous_step;
    } else if (options.predictor == Predictor::tangent) {
      core::Matrix J;
      if (system.jacobian(x, J) == core::EvalStatus::ok) {
        // dF/dx . rate = 0, dp/dx . rate = 1: the last of J's rows (m + 1 >= n of them; least
        // squares when the system is overdetermined).
        core::Vector rhs = core::Vector::Zero(J.rows());
        rhs[J.rows() - 1] = 1.0;
        core::Vector candidate = J.colPivHouseholderQr().solve(rhs);
        if (candidate.allFinite()) rate = candidate;
      }
    }
    core::Vector y;
    double step = 0;
    const CorrectedStep corrected = correct_with_shrinking(
        ds, index, options, hooks, y,
        [&](double ds_try, core::Vector& predicted) {
          step = parameter.direction * ds_try * unit;
          predicted = x + step * rate;
          system.set_value(lambda + step);
          return corrector.solve(system, predicted);
        },
        [](const core::Vector& v) { return v; });
    ds = corrected.ds;
    s = corrected.summary;
    const core::NewtonStatus last_failure = corrected.last_failure;
    const std::string& last_message = corrected.last_message;
    if (!corrected.accepted) {
      branch.reason = last_failure == core::NewtonStatus::evaluation_failed
                          ? StopReason::evaluation_failed
                          : StopReason::step_floor;
      branch.message = fmt::format(
          "no point {} could be corrected at {} = {:.10g} +- steps >= ds_min = {:.3g} (a fold in "
          "{}?) from {} (last Newton status {}: {})",
          index, parameter.name, lambda, options.ds_min, parameter.name, describe_point(x),
          core::to_string(last_failure), last_message);
      return branch;
    }
    arclength += (y - x).norm();
    BranchPoint point =
        recorder.finish(y, index, s.iterations, ds, arclength, index + 1 == options.max_points);
    double bound_value = 0;
    if (const Bound* bound = recorder.violated_bound(point, bound_value)) {
      branch.reason = StopReason::bound_reached;
      branch.message = fmt::format("{} reached its bound {:.6g} after point {}", bound->observable,
                                   bound_value, index - 1);
      return branch;
    }
    branch.points.push_back(std::move(point));
    if (hooks.on_point) hooks.on_point(branch.points.back());
    previous = x;
    previous_step = step;
    x = y;
    lambda += step;
    ds = adapted_step(ds, s.iterations, options);
  }
  return reached_max_points(std::move(branch));
}

}  // namespace backbone::continuation
