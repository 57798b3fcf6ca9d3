// Natural-parameter continuation: prescribe one scalar p(x), step it, correct the rest.
//
// The scalar is either one unknown (e.g. the period, as the paper does: fix T, solve for u0)
// or a named observable of the problem (energy, amplitude...). Each point solves the square
// system [F(x); p(x) - lambda] = 0 (ParameterConstraintSystem, itself a core::Problem) at
// lambda_k = lambda_0 + direction * sum of steps, from a secant or tangent predictor. It cannot
// pass a fold in p: there Newton fails, ds shrinks to ds_min and the branch ends with
// StopReason::step_floor, keeping the points computed so far (switching.hpp then hands over to
// pseudo-arclength). With options.scale_unknowns an unknown parameter steps by
// ds * typical_scale (ds dimensionless, as in pseudo-arclength); an observable steps in its own
// units. The loop prints nothing.
//
//   auto newton = core::make_corrector("eigen", core::NewtonOptions{});
//   ContinuationOptions opt; opt.method = Method::natural; opt.ds = 0.05; opt.max_points = 20;
//   NaturalParameter amplitude = NaturalParameter::of_unknown(0, "amplitude");
//   Branch b = natural(duffing, guess, amplitude, *newton, opt);   // A = A0, A0 + 0.05, ...
//   NaturalParameter energy = NaturalParameter::of_observable("energy", -1.0);  // decreasing
#pragma once

#include <string>

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "core/newton.hpp"
#include "core/problem.hpp"

namespace backbone::continuation {

struct NaturalParameter {
  enum class Kind { unknown, observable };
  Kind kind = Kind::unknown;
  int index = 0;           // Kind::unknown: position in x
  std::string name;        // Kind::observable: observable name; Kind::unknown: label
  double direction = 1.0;  // +1: increasing, -1: decreasing

  static NaturalParameter of_unknown(int index, std::string label, double direction = 1.0);
  static NaturalParameter of_observable(std::string name, double direction = 1.0);
};

// Value of the parameter at x; NaN if the observable is not reported or evaluation fails.
double parameter_value(const core::Problem& problem, const NaturalParameter& parameter,
                       const core::Vector& x);

// [F(x); p(x) - value]. The last Jacobian row is e_index for an unknown, central differences
// of the observable otherwise (observables are cheap closed forms of x in every problem here).
// An observable's row is divided by |value| (1 when value = 0): an energy of 1e-3 J must not
// weigh 1e-4 against residual rows of order one when an overdetermined system is solved in the
// least-squares sense (measured: Newton then crawls, 3.8e-5 -> 3.0e-5 in 25 iterations).
class ParameterConstraintSystem : public core::Problem {
 public:
  ParameterConstraintSystem(const core::Problem& base, NaturalParameter parameter, double value);
  int num_unknowns() const override { return base_.num_unknowns(); }
  int num_equations() const override { return base_.num_equations() + 1; }
  std::string name() const override { return base_.name() + " + " + parameter_.name + " fixed"; }
  core::Observables observables(const core::Vector& x) const override {
    return base_.observables(x);
  }
  core::Vector typical_scale() const override { return base_.typical_scale(); }
  void set_value(double value) { value_ = value; }
  // Divisor of the constraint row: 1 for an unknown, |value| (or 1 at 0) for an observable.
  double row_scale() const;

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override;
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override;

 private:
  const core::Problem& base_;
  NaturalParameter parameter_;
  double value_;
};

// Throws core::InputError for bad options, sizes, an unknown index out of range or an
// observable the problem does not report at the guess. Never throws on numerical failure.
Branch natural(const core::Problem& problem, const core::Vector& guess,
               const NaturalParameter& parameter, core::Corrector& corrector,
               const ContinuationOptions& options, const ContinuationHooks& hooks = {});

}  // namespace backbone::continuation
