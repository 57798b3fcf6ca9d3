// The conservative Duffing oscillator x'' + x + x^3 = 0 as a periodic-orbit problem.
//
// Unknowns [x0 | T] (core::PeriodicOrbitProblem layout, state size 1, no parameters): the orbit
// starts at rest at amplitude x0 (v0 = 0). Residuals (README.md, 'Residuals and Jacobians'):
//   displacement_periodicity ("paper"):  (x0 - x(T)) / |x0|       (double root on the backbone)
//   half_period_velocity ("regular"):    v(T/2) / v_max(x0)       (simple root, J ~ [2, 1])
// Both are made dimensionless by the orbit's own scale (v_max = sqrt(2 V(x0)), the largest
// speed on the orbit), so one Newton tolerance means the same relative accuracy from
// amplitude 0.01 to 10 (an absolute ||v|| <= 1e-10 would pin T to 2e-8 at A = 0.01).
// The flow comes from CVODE (cvode_integrator.hpp, Adams, rtol 1e-13); the Jacobian is
// analytic, from the variational equations integrated alongside. exact_period is the oracle:
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

#include "core/periodic_orbit.hpp"
#include "problems/duffing/cvode_integrator.hpp"

namespace backbone::duffing {

// Potential V(x) = x^2/2 + x^4/4.
double potential(double x);

// Exact period of the orbit of amplitude A > 0. With x = A sin(theta) the integral becomes
// 4 int_0^{pi/2} dtheta / sqrt(1 + A^2 (1 + sin^2 theta) / 2), a smooth, even, pi-periodic
// integrand: the trapezoidal rule over a period converges geometrically; nodes are doubled
// until two successive values agree to 1e-15 (relative). Closed form for cross-checks:
// 4 K(k) / sqrt(1 + A^2), k^2 = A^2 / (2 (1 + A^2)).
double exact_period(double amplitude);

// Divisor of the residual and its derivative with respect to x0 (see above).
struct ResidualScale {
  double value = 1;
  double derivative = 0;
};
ResidualScale residual_scale(double amplitude, core::ShootingFormulation formulation);

struct DuffingOptions {
  double relative_tolerance = 1e-13;  // CVODE rtol; absolute tolerances scale with the orbit
  void validate() const;              // InputError("rtol", ...)
};

class Duffing : public core::PeriodicOrbitProblem {
 public:
  explicit Duffing(DuffingOptions options = {});
  std::string name() const override { return "duffing"; }
  int state_size() const override { return 1; }
  double energy(const core::Vector& x) const override { return potential(x[0]); }
  // period, frequency, energy, amplitude.
  core::Observables observables(const core::Vector& x) const override;
  core::Vector typical_scale() const override;

  // Flow from (x0, 0) over time t: (x, v) and, with sensitivities, (dx/dx0, dv/dx0).
  // Returns false when CVODE fails.
  bool flow(double x0, double t, double& x, double& v, double* dx_dx0 = nullptr,
            double* dv_dx0 = nullptr) const;

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override;
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override;

 private:
  DuffingOptions options_;
};

// Scene keys of the Duffing problem (amplitude, period_guess, rtol) with defaults.
boost::program_options::options_description scene_keys();

}  // namespace backbone::duffing
