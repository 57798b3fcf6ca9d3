// Natural-parameter continuation: prescribe one scalar p(x), step it, correct the rest.
//
// The scalar is either one unknown (e.g. the period, as the paper does: fix T, solve for u0)
// or a named observable of the problem (energy, amplitude...). Each point solves the square
// system [F(x); p(x) - lambda] = 0 (F bordered by one parameter row,
// core/solvers/bordered_system.hpp; ParameterConstraintSystem below) at lambda_k = lambda_0 +
// direction * sum of steps, from a secant or tangent predictor. It cannot pass a fold in p: there
// Newton fails, ds shrinks to ds_min and the branch ends with StopReason::step_floor, keeping the
// points computed so far (switching.hpp then hands over to pseudo-arclength). The loop shares with
// pseudo-arclength (loop_steps.hpp, continuation/README.md) the scaled unknowns
// (options.scale_unknowns: an unknown parameter steps by ds * typical_scale, an observable in its
// own units), the arclength column (sum of chords in the scaled unknowns, the same units as
// pseudo-arclength's), the first-point and step checks of hooks.reject_point and landing on bounds
// (the last point lies on the bound). The loop prints nothing.
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
#include "continuation/restart.hpp"
#include "core/problem.hpp"
#include "core/solvers/bordered_system.hpp"
#include "core/solvers/newton.hpp"

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

// The row p(x) - value of a core::BorderedSystem over `problem`: a fixed unknown (e_index .
// x - value) or an observable row (divided by |value|, 1 when value = 0: an energy of 1e-3 J
// must not weigh 1e-3 against residual rows of order one when an overdetermined system is
// solved in the least-squares sense; measured: Newton then crawls, 3.8e-5 -> 3.0e-5 in 25
// iterations). Throws core::InputError for an unknown index out of range.
core::BorderRow parameter_row(const core::Problem& problem, const NaturalParameter& parameter,
                              double value);

// [F(x); p(x) - value]: the bordered system with the one row parameter_row(...), under the name
// callers know it by. set_value moves the prescribed value.
class ParameterConstraintSystem : public core::BorderedSystem {
 public:
  ParameterConstraintSystem(const core::Problem& base, const NaturalParameter& parameter,
                            double value)
      : BorderedSystem(base, {parameter_row(base, parameter, value)}) {}
  using BorderedSystem::set_value;
  void set_value(double value) { set_value(0, value); }
};

// Throws core::InputError for bad options, sizes, an unknown index out of range or an
// observable the problem does not report at the guess. Never throws on numerical failure.
// start: index and arclength of the first point (restart.hpp).
Branch natural(const core::Problem& problem, const core::Vector& guess,
               const NaturalParameter& parameter, core::Corrector& corrector,
               const ContinuationOptions& options, const ContinuationHooks& hooks = {},
               const BranchStart& start = {});

// Continues a branch from the loop state saved with one of its points (BranchPoint::state), bit
// for bit as the run that saved it (pseudo_arclength.hpp has the same entry point).
Branch natural(const core::Problem& problem, const LoopState& from, bool record_from,
               const NaturalParameter& parameter, core::Corrector& corrector,
               const ContinuationOptions& options, const ContinuationHooks& hooks = {});

}  // namespace backbone::continuation
