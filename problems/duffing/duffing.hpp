// The conservative Duffing oscillator x'' + x + x^3 = 0 as a periodic-orbit problem.
//
// A core::OdeOrbitProblem of dimension 1 (core/orbits/ode_orbit.hpp): unknowns [x0 | T], the orbit
// starts at rest at amplitude x0 (v0 = 0); the flow (CVODE, Adams, rtol 1e-13), both shooting
// formulations and the analytic Jacobian (variational equations) come from core. Residuals
// (README.md, section 'Residuals and Jacobians'):
//   displacement_periodicity ("paper"):  (x0 - x(T)) / |x0|       (double root on the backbone)
//   half_period_velocity ("regular"):    v(T/2) / v_max(x0)       (simple root, J ~ [2, 1])
// with v_max = sqrt(2 V(x0)), the largest speed on the orbit. exact_period is the oracle:
// T(A) = 4 int_0^A dx / sqrt(2 (V(A) - V(x))), V = x^2/2 + x^4/4, by quadrature.
//
//   Duffing duffing;                                    // regular formulation by default
//   core::Vector x(2); x << 1.0, exact_period(1.0);      // on the backbone
//   core::Vector r; core::Matrix J;
//   duffing.residual(x, r);                              // |r[0]| ~ 1e-13
//   duffing.jacobian(x, J);                              // ~ [2.0, 1.0] / 1.22: simple root
//   duffing.set_formulation(core::ShootingFormulation::displacement_periodicity);
//   duffing.jacobian(x, J);                              // ~ [0, 0]: double root
//   double E = duffing.energy(x);                        // V(1) = 0.75
#pragma once

#include <boost/program_options.hpp>

#include "core/orbits/ode_orbit.hpp"

namespace backbone::duffing {

// Potential V(x) = x^2/2 + x^4/4.
double potential(double x);

// Exact period of the orbit of amplitude A > 0. With x = A sin(theta) the integral becomes
// 4 int_0^{pi/2} dtheta / sqrt(1 + A^2 (1 + sin^2 theta) / 2), a smooth, even, pi-periodic
// integrand: the trapezoidal rule over a period converges geometrically; nodes are doubled
// until two successive values agree to 1e-15 (relative). Closed form for cross-checks:
// 4 K(k) / sqrt(1 + A^2), k^2 = A^2 / (2 (1 + A^2)).
double exact_period(double amplitude);

// relative_tolerance is the scene key rtol.
using DuffingOptions = core::OdeOrbitOptions;

class Duffing : public core::OdeOrbitProblem {
 public:
  explicit Duffing(DuffingOptions options = {}) : OdeOrbitProblem(1, options) {}
  std::string name() const override { return "duffing"; }
  void acceleration(const double* q, double* a) const override;
  void acceleration_jacobian(const double* q, core::Matrix& J) const override;
  double energy(const core::Vector& x) const override { return potential(x[0]); }
  // period, frequency, energy, amplitude.
  core::Observables observables(const core::Vector& x) const override;
  core::Vector typical_scale() const override;  // (1, 2 pi): amplitude, linear period
};

// Scene keys of the Duffing problem (amplitude, period_guess, rtol) with defaults.
boost::program_options::options_description scene_keys();

}  // namespace backbone::duffing
