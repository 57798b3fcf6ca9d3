// A periodic-orbit problem: shooting residual on (initial state, period, parameters).
//
// Unknown layout, written down once (BifurcationKit's convention):
//     x = [ s_0 ... s_{S-1} | T | p_0 ... p_{P-1} ]
//          state samples      period   parameters
// with S = state_size(), index of T = period_index() = S, P = num_parameters().
// The orbits sought start at rest (v0 = 0), so the state samples are initial *displacements*
// (for a field problem: nodal values of u0; for an ODE: the positions).
//
// Two shooting formulations (core/README.md, section 'Shooting formulations'):
//  - displacement_periodicity: the paper's f = u0 - u(u0, T). A double root on the family: the
//    period column vanishes and Newton converges linearly; kept to compare against.
//  - half_period_velocity: reversibility, an orbit with v0 = 0 is T-periodic iff
//    v(., T/2) = 0 (for fields: projected on the hat functions). Regular: the default.
// Either way the residual has S equations (+ constraints a subclass adds), so the family of
// orbits is (at least) a curve: n_unknowns - n_equations = 1 + P.
//
//   class Duffing : public PeriodicOrbitProblem { ... state_size() == 1 ... };
//   Vector x(2); x << amplitude, period_guess;
//   duffing.set_formulation(ShootingFormulation::half_period_velocity);
//   newton->solve(duffing, x);  // x[duffing.period_index()] is now the period
#pragma once

#include <numbers>
#include <string>

#include "core/problem.hpp"

namespace backbone::core {

enum class ShootingFormulation { displacement_periodicity, half_period_velocity };
const char* to_string(ShootingFormulation f);
// The scene key's value for f: "regular" (half_period_velocity) or "paper"
// (displacement_periodicity), what `formulation =` takes and run logs echo.
const char* scene_name(ShootingFormulation f);
// Accepts "paper" / "displacement_periodicity" and "regular" / "half_period_velocity".
// Throws InputError("formulation", ...) otherwise.
ShootingFormulation parse_formulation(const std::string& name);

class PeriodicOrbitProblem : public Problem {
 public:
  virtual int state_size() const = 0;
  virtual int num_parameters() const { return 0; }
  int period_index() const { return state_size(); }
  int num_unknowns() const override { return state_size() + 1 + num_parameters(); }
  int num_equations() const override { return state_size(); }

  double period(const Vector& x) const { return x[period_index()]; }
  double frequency(const Vector& x) const { return 2.0 * std::numbers::pi / period(x); }
  // Energy of the orbit (conserved along it). For v0 = 0 orbits: the potential energy of the
  // initial state.
  virtual double energy(const Vector& x) const = 0;

  // Coordinates of the state samples, for orbits.csv (node positions of a field problem;
  // 0..S-1 for an ODE).
  virtual Vector state_coordinates() const;
  // The initial state of the orbit at x as (coordinate, value) samples: the rows of
  // orbits.csv. Default: state_coordinates() paired with the state entries. A problem whose
  // state holds more than values at fixed coordinates (e.g. a free knot) overrides it.
  virtual void initial_state_samples(const Vector& x, Vector& coordinates, Vector& values) const;

  // Default observables: period, frequency, energy (columns of branch.csv).
  Observables observables(const Vector& x) const override;

  ShootingFormulation formulation() const { return formulation_; }
  void set_formulation(ShootingFormulation f) { formulation_ = f; }

 private:
  ShootingFormulation formulation_ = ShootingFormulation::half_period_velocity;
};

}  // namespace backbone::core
