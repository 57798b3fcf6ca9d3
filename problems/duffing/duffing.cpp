#include "problems/duffing/duffing.hpp"

#include <cmath>
#include <numbers>

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

void Duffing::acceleration(const double* q, double* a) const {
  a[0] = -q[0] - q[0] * q[0] * q[0];
}

void Duffing::acceleration_jacobian(const double* q, core::Matrix& J) const {
  J.resize(1, 1);
  J(0, 0) = -(1.0 + 3.0 * q[0] * q[0]);
}

core::Observables Duffing::observables(const core::Vector& x) const {
  core::Observables o = OdeOrbitProblem::observables(x);
  o.emplace_back("amplitude", x[0]);
  return o;
}

core::Vector Duffing::typical_scale() const {
  core::Vector s(2);
  s << 1.0, 2.0 * std::numbers::pi;
  return s;
}

boost::program_options::options_description scene_keys() {
  namespace po = boost::program_options;
  po::options_description keys("duffing (x'' + x + x^3 = 0)");
  keys.add_options()  //
      ("amplitude", po::value<double>()->default_value(0.01),
       "starting amplitude x0 of the backbone (v0 = 0) [dimensionless] (> 0)")  //
      ("period_guess", po::value<double>(),
       "starting guess of the period [dimensionless] (> 0; default: the linear period 2 pi)")  //
      ("rtol", po::value<double>()->default_value(1e-13),
       "CVODE relative tolerance [-] (in (0, 1e-3))");
  return keys;
}

}  // namespace backbone::duffing
