#include "problems/duffing/duffing.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "core/errors.hpp"

namespace backbone::duffing {

double potential(double x) {
  return 0.5 * x * x + 0.25 * x * x * x * x;
}

double exact_period(double amplitude) {
  const double a2 = amplitude * amplitude;
  const auto integrand = [a2](double theta) {
    const double s = std::sin(theta);
    return 1.0 / std::sqrt(1.0 + 0.5 * a2 * (1.0 + s * s));
  };
  // Trapezoid over [0, pi/2] with half-weighted ends == trapezoid over the full period (the
  // integrand is even about 0 and pi/2): spectrally accurate.
  double previous = 0;
  for (int nodes = 8; nodes <= (1 << 20); nodes *= 2) {
    const double h = 0.5 * std::numbers::pi / nodes;
    double sum = 0.5 * (integrand(0.0) + integrand(0.5 * std::numbers::pi));
    for (int i = 1; i < nodes; ++i) sum += integrand(i * h);
    const double value = 4.0 * h * sum;
    if (nodes > 8 && std::abs(value - previous) <= 1e-15 * std::abs(value)) return value;
    previous = value;
  }
  return previous;
}

void DuffingOptions::validate() const {
  if (!(relative_tolerance > 0 && relative_tolerance < 1e-3))
    throw core::InputError("rtol",
                           fmt::format("must be in (0, 1e-3) (got {})", relative_tolerance));
}

Duffing::Duffing(DuffingOptions options) : options_(options) {
  options_.validate();
}

core::Observables Duffing::observables(const core::Vector& x) const {
  core::Observables o = PeriodicOrbitProblem::observables(x);
  o.emplace_back("amplitude", x[0]);
  return o;
}

core::Vector Duffing::typical_scale() const {
  core::Vector s(2);
  s << 1.0, 2.0 * std::numbers::pi;
  return s;
}

bool Duffing::flow(double x0, double t, double& x, double& v, double* dx_dx0,
                   double* dv_dx0) const {
  if (t == 0) {
    x = x0;
    v = 0;
    if (dx_dx0) *dx_dx0 = 1;
    if (dv_dx0) *dv_dx0 = 0;
    return true;
  }
  const bool sensitivities = dx_dx0 != nullptr;
  // Absolute tolerances a factor 1e-3 below rtol times each component's scale on the orbit,
  // so that the relative tolerance governs even near the zero crossings.
  const double amplitude = std::max(std::abs(x0), 1e-300);
  const double speed = std::sqrt(2.0 * potential(amplitude));
  const double stiffness = 1.0 + 3.0 * amplitude * amplitude;
  CvodeOptions cv;
  cv.relative_tolerance = options_.relative_tolerance;
  const double floor = 1e-3 * options_.relative_tolerance;
  core::Vector y;
  if (sensitivities) {
    y.resize(4);
    y << x0, 0.0, 1.0, 0.0;
    cv.absolute_tolerance.resize(4);
    cv.absolute_tolerance << floor * amplitude, floor * speed, floor, floor * std::sqrt(stiffness);
  } else {
    y.resize(2);
    y << x0, 0.0;
    cv.absolute_tolerance.resize(2);
    cv.absolute_tolerance << floor * amplitude, floor * speed;
  }
  const RightHandSide rhs = [sensitivities](double, const double* s, double* ds) {
    ds[0] = s[1];
    ds[1] = -s[0] - s[0] * s[0] * s[0];
    if (sensitivities) {
      ds[2] = s[3];
      ds[3] = -(1.0 + 3.0 * s[0] * s[0]) * s[2];
    }
  };
  IntegrationResult r = integrate(rhs, y, t, cv);
  if (!r.ok) return false;
  x = y[0];
  v = y[1];
  if (sensitivities) {
    *dx_dx0 = y[2];
    if (dv_dx0) *dv_dx0 = y[3];
  }
  return true;
}

ResidualScale residual_scale(double amplitude, core::ShootingFormulation formulation) {
  const double a = std::max(std::abs(amplitude), 1e-300);
  const double sign = amplitude < 0 ? -1.0 : 1.0;
  if (formulation == core::ShootingFormulation::half_period_velocity) {
    const double speed = std::sqrt(2.0 * potential(a));
    return {speed, sign * (a + a * a * a) / speed};
  }
  return {a, sign};
}

core::EvalStatus Duffing::compute_residual(const core::Vector& x, core::Vector& r) const {
  const double period = x[period_index()];
  if (!(period > 0) || !std::isfinite(x[0])) return core::EvalStatus::failed;
  double position = 0, velocity = 0;
  const ResidualScale scale = residual_scale(x[0], formulation());
  if (formulation() == core::ShootingFormulation::half_period_velocity) {
    if (!flow(x[0], 0.5 * period, position, velocity)) return core::EvalStatus::failed;
    r[0] = velocity / scale.value;
  } else {
    if (!flow(x[0], period, position, velocity)) return core::EvalStatus::failed;
    r[0] = (x[0] - position) / scale.value;
  }
  return core::EvalStatus::ok;
}

core::EvalStatus Duffing::compute_jacobian(const core::Vector& x, core::Matrix& J) const {
  const double period = x[period_index()];
  if (!(period > 0) || !std::isfinite(x[0])) return core::EvalStatus::failed;
  double position = 0, velocity = 0, dx_dx0 = 0, dv_dx0 = 0, raw = 0;
  const auto acceleration = [](double q) { return -q - q * q * q; };
  if (formulation() == core::ShootingFormulation::half_period_velocity) {
    // r = v(T/2): dr/dx0 = dv/dx0 (T/2), dr/dT = a(T/2) / 2.
    if (!flow(x[0], 0.5 * period, position, velocity, &dx_dx0, &dv_dx0))
      return core::EvalStatus::failed;
    J(0, 0) = dv_dx0;
    J(0, 1) = 0.5 * acceleration(position);
    raw = velocity;
  } else {
    // r = x0 - x(T): dr/dx0 = 1 - dx/dx0 (T), dr/dT = -v(T).
    if (!flow(x[0], period, position, velocity, &dx_dx0, &dv_dx0)) return core::EvalStatus::failed;
    J(0, 0) = 1.0 - dx_dx0;
    J(0, 1) = -velocity;
    raw = x[0] - position;
  }
  // d(raw / s)/dx0 = raw'/s - raw s'/s^2 (product rule; the second term vanishes on orbits).
  const ResidualScale scale = residual_scale(x[0], formulation());
  J /= scale.value;
  J(0, 0) -= raw * scale.derivative / (scale.value * scale.value);
  return core::EvalStatus::ok;
}

boost::program_options::options_description scene_keys() {
  namespace po = boost::program_options;
  po::options_description keys("duffing (x'' + x + x^3 = 0)");
  keys.add_options()  //
      ("amplitude", po::value<double>()->default_value(0.01),
       "starting amplitude x0 of the backbone (v0 = 0) [length]")  //
      ("period_guess", po::value<double>(),
       "starting guess of the period [time] (default: the linear period 2 pi)")  //
      ("rtol", po::value<double>()->default_value(1e-13), "CVODE relative tolerance [-]");
  return keys;
}

}  // namespace backbone::duffing
