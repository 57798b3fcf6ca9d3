#include "continuation/methods/natural.hpp"

#include <fmt/format.h>

#include <cmath>

#include "continuation/internal/loop_steps.hpp"
#include "continuation/scaled_problem.hpp"
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
  return core::observable_value(problem, parameter.name, x);
}

core::BorderRow parameter_row(const core::Problem& problem, const NaturalParameter& parameter,
                              double value) {
  if (parameter.kind == NaturalParameter::Kind::observable)
    return core::BorderRow::observable(parameter.name, value);
  if (parameter.index < 0 || parameter.index >= problem.num_unknowns())
    throw core::InputError("natural_parameter",
                           fmt::format("unknown index {} out of range [0, {})", parameter.index,
                                       problem.num_unknowns()));
  return core::BorderRow::fixed_unknown(problem.num_unknowns(), parameter.index, value,
                                        parameter.name + " fixed");
}

namespace {

// What the natural loop carries from one step to the next: the point, its parameter value and
// the next step, and the point and parameter step before it (the secant predictor).
struct NaturalState {
  core::Vector x;
  double lambda = 0;
  double ds = 0;
  core::Vector previous;
  double previous_step = 0;
};

// The state the next step starts from, saved with each point for a restart.
std::shared_ptr<LoopState> saved_state(const core::Vector& z, double value,
                                       const core::Vector& before, double step, double next_ds) {
  auto state = std::make_shared<LoopState>();
  state->method = Method::natural;
  state->z = z;
  state->lambda = value;
  state->previous = before;
  state->previous_step = step;
  state->ds = next_ds;
  return state;
}

// The parameter in the problem's units, for messages.
double in_units(const ScaledProblem& problem, const NaturalParameter& parameter, double lambda) {
  return parameter.kind == NaturalParameter::Kind::unknown
             ? lambda * problem.scale()[parameter.index]
             : lambda;
}

// dx/dlambda for the predictor: tangent of the curve scaled so that dp = 1, or the secant; zero
// (the last point as the prediction) for neither or where the tangent cannot be solved for.
core::Vector predictor_rate(const ParameterConstraintSystem& system, const NaturalState& s,
                            const ContinuationOptions& options, int n) {
  core::Vector rate = core::Vector::Zero(n);
  if (options.predictor == Predictor::secant && s.previous_step != 0) {
    rate = (s.x - s.previous) / s.previous_step;
  } else if (options.predictor == Predictor::tangent) {
    core::Matrix J;
    if (system.jacobian(s.x, J) == core::EvalStatus::ok) {
      // dF/dx . rate = 0, dp/dx . rate = 1: the last of J's rows (m + 1 >= n of them; least
      // squares when the system is overdetermined).
      core::Vector rhs = core::Vector::Zero(J.rows());
      rhs[J.rows() - 1] = 1.0;
      core::Vector candidate = J.colPivHouseholderQr().solve(rhs);
      if (candidate.allFinite()) rate = candidate;
    }
  }
  return rate;
}

// The loop proper, in the scaled unknowns z of `problem` (in_scaled_unknowns): an unknown
// parameter is then z_index, stepped by ds (ds times its typical scale in the problem's units).
// It starts from guess (corrected at its own parameter value) or, with `from`, continues from a
// saved state (restart.hpp) without correcting anything. Each step: predictor_rate, the
// corrected step (ds shrinking on failure), record with the state after it (ds adapted), then
// the state moves on.
Branch natural_loop(const ScaledProblem& problem, const core::Vector& guess,
                    const NaturalParameter& parameter, const LoopState* from, bool record_from,
                    const BranchStart& start, core::Corrector& corrector,
                    const ContinuationOptions& options, const ContinuationHooks& hooks) {
  const int n = problem.num_unknowns();
  LoopSteps steps(problem, corrector, options, hooks, start);
  // The row's value is the parameter's at the last point (an observable row is divided by it).
  const double lambda0 = from ? from->lambda : parameter_value(problem, parameter, guess);
  ParameterConstraintSystem system(problem, parameter, lambda0);
  NaturalState s;
  s.x = from ? from->z : guess;
  s.lambda = lambda0;
  s.ds = from ? from->ds : options.ds;
  s.previous = from ? from->previous : s.x;
  s.previous_step = from ? from->previous_step : 0;
  if (from) {
    steps.resume(*from, record_from);
    if (!record_from) steps.remember_saved_point(s.x);
  } else {
    if (!steps.start(
            system, s.x,
            fmt::format(" at {} = {:.10g}", parameter.name, in_units(problem, parameter, lambda0))))
      return steps.take();
    s.previous = s.x;
    steps.report_first(saved_state(s.x, s.lambda, s.x, 0.0, s.ds));
  }
  while (steps.begin_step()) {
    const int index = steps.next_index();
    const core::Vector rate = predictor_rate(system, s, options, n);
    core::Vector y;
    double step = 0;
    const CorrectedStep corrected =
        steps.correct(s.ds, y, [&](double ds_try, core::Vector& predicted) {
          step = parameter.direction * ds_try;
          predicted = s.x + step * rate;
          system.set_value(s.lambda + step);
          return corrector.solve(system, predicted);
        });
    s.ds = corrected.ds;
    if (!corrected.accepted)
      return steps.end(
          corrected.last_failure == core::NewtonStatus::evaluation_failed
              ? StopReason::evaluation_failed
              : StopReason::step_floor,
          fmt::format("no point {} could be corrected at {} = {:.10g} +- steps >= ds_min = "
                      "{:.3g} (a fold in {}?) from {} (last Newton status {}: {})",
                      index, parameter.name, in_units(problem, parameter, s.lambda), options.ds_min,
                      parameter.name, steps.describe(s.x), core::to_string(corrected.last_failure),
                      corrected.last_message));
    const int iterations = corrected.summary.iterations;
    const double next_ds = adapted_step(s.ds, iterations, options);
    if (!steps.record(s.x, y, y - s.x, iterations, s.ds, index + 1 == options.max_points,
                      saved_state(y, s.lambda + step, s.x, step, next_ds)))
      return steps.take();
    s.previous = s.x;
    s.previous_step = step;
    s.x = y;
    s.lambda += step;
    s.ds = next_ds;
  }
  return steps.take();
}

}  // namespace

namespace {

void check_parameter(const core::Problem& problem, const core::Vector& x,
                     const NaturalParameter& parameter) {
  const int n = problem.num_unknowns();
  if (parameter.kind == NaturalParameter::Kind::unknown &&
      (parameter.index < 0 || parameter.index >= n))
    throw core::InputError("natural_parameter", fmt::format("unknown index {} out of range [0, {})",
                                                            parameter.index, n));
  if (!(parameter.direction == 1.0 || parameter.direction == -1.0))
    throw core::InputError("natural_direction",
                           fmt::format("must be +1 or -1 (got {})", parameter.direction));
  if (!std::isfinite(parameter_value(problem, parameter, x)))
    throw core::InputError(
        "natural_parameter",
        fmt::format("the problem reports no finite observable '{}' at the guess", parameter.name));
}

}  // namespace

Branch natural(const core::Problem& problem, const core::Vector& guess,
               const NaturalParameter& parameter, core::Corrector& corrector,
               const ContinuationOptions& options, const ContinuationHooks& hooks,
               const BranchStart& start) {
  options.validate();
  check_sizes(problem, guess, core::Vector(), "natural continuation in one parameter");
  check_parameter(problem, guess, parameter);
  return in_scaled_unknowns(problem, options, hooks,
                            [&](const ScaledProblem& scaled, const ContinuationHooks& inner) {
                              return natural_loop(scaled, scaled.to_scaled(guess), parameter,
                                                  nullptr, false, start, corrector, options, inner);
                            });
}

Branch natural(const core::Problem& problem, const LoopState& from, bool record_from,
               const NaturalParameter& parameter, core::Corrector& corrector,
               const ContinuationOptions& options, const ContinuationHooks& hooks) {
  options.validate();
  check_sizes(problem, from.z, core::Vector(), "natural continuation in one parameter");
  check_parameter(problem, from.unknowns(), parameter);
  if (const std::string why = state_mismatch(from, problem, options, Method::natural); !why.empty())
    throw core::InputError("state", why);
  return in_scaled_unknowns(problem, options, hooks,
                            [&](const ScaledProblem& scaled, const ContinuationHooks& inner) {
                              return natural_loop(scaled, from.z, parameter, &from, record_from, {},
                                                  corrector, options, inner);
                            });
}

}  // namespace backbone::continuation
