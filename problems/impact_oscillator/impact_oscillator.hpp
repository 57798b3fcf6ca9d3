// The harmonically forced impact oscillator (Budd & Dux; Nordmark): a forced hybrid problem.
//
//     x'' + x = cos(omega t)   while x < sigma,
//     at x = sigma (rising):   v -> -r v          (Newton's restitution law, 0 < r <= 1)
//
// A core::HybridOrbitProblem (core/orbits/hybrid_orbit.hpp): state y = (x, v), parameters
// frequency omega, restitution r and wall sigma (any of them free), period 2 pi m / omega for an
// orbit of m forcing periods; the shooting, the saltation matrices and the monodromy come from
// core. Observables: period, frequency, restitution, wall, impacts_per_period, impact_velocity
// (the smallest speed at an impact, 0 at grazing).
//
// The period-1 orbit with one impact per forcing period has a closed form (README.md, section
// 'The period-1 orbit'), the tests' oracle: period_one_orbit gives its impact phase and speed,
// its state at t = 0 and its multipliers (eig(S R)).
//
//   ImpactOscillator oscillator;                        // omega 2.8, r 0.8, sigma 0
//   oscillator.set_free_parameter("wall");
//   PeriodOneOrbit exact = period_one_orbit(2.8, 0.8, 0.0);
//   core::Vector x(3); x << exact.start, 0.0;           // [x0, v0 | sigma]
//   core::Vector r; oscillator.residual(x, r);          // |r| ~ 1e-12
#pragma once

#include <array>
#include <boost/program_options.hpp>
#include <complex>
#include <memory>
#include <optional>

#include "core/orbits/hybrid_orbit.hpp"

namespace backbone::impact_oscillator {

class ImpactOscillator : public core::HybridOrbitProblem {
 public:
  // Parameters frequency 2.8, restitution 0.8, wall 0 unless set (set_parameter).
  explicit ImpactOscillator(core::HybridOrbitOptions options = {});
  std::string name() const override { return "impact_oscillator"; }
  std::unique_ptr<core::Problem> clone() const override {
    return std::make_unique<ImpactOscillator>(*this);
  }
  void field(double t, const double* y, const core::Vector& p, double* dy) const override;
  void field_jacobian(double t, const double* y, const core::Vector& p,
                      core::Matrix& J) const override;
  bool forced() const override { return true; }
  double forcing_period(const core::Vector& p) const override;
  int num_events() const override { return 1; }
  double event(int k, double t, const double* y, const core::Vector& p) const override;
  void reset(int k, const double* y, const core::Vector& p, double* y_plus) const override;
  // Symplectic (det M = 1, multipliers mu, 1/mu) when no energy is lost at impacts (r = 1).
  core::FloquetStructure floquet_structure() const override;
  std::string event_count_name() const override { return "impacts_per_period"; }
  std::string event_speed_name() const override { return "impact_velocity"; }
  std::string event_gap_name() const override { return "wall_gap"; }
};

// The period-1 orbit with one impact per forcing period (README.md, 'The period-1 orbit').
struct PeriodOneOrbit {
  double phase = 0;                                 // omega t* of the impact, in [0, 2 pi)
  double impact_velocity = 0;                       // V > 0, the speed just before the impact
  core::Vector start;                               // (x, v) at t = 0 (and t = 2 pi / omega)
  std::array<std::complex<double>, 2> multipliers;  // eigenvalues of S R(2 pi / omega)
};
// nullopt when no such orbit exists (the quadratic for V has no positive root: beyond grazing)
// or omega is a multiple of 1 (resonance: no particular solution).
std::optional<PeriodOneOrbit> period_one_orbit(double omega, double r, double sigma);

// The wall where the period-1 orbit's closed-form multipliers pass -1 (1 + tr M + r^2 = 0), by
// bisection over [lo, hi] to machine precision; NaN when no orbit exists at an end or the sign
// does not change there.
double period_doubling_wall(double omega, double r, double lo, double hi);

// Scene keys of the impact oscillator (frequency, restitution, wall, wall_min, wall_max, rtol,
// continuation_parameter) with defaults.
boost::program_options::options_description scene_keys();

}  // namespace backbone::impact_oscillator
