#include "problems/impact_oscillator/impact_oscillator.hpp"

#include <cmath>
#include <limits>
#include <numbers>

namespace backbone::impact_oscillator {

namespace {
constexpr int frequency = 0, restitution = 1, wall = 2;
}

ImpactOscillator::ImpactOscillator(core::HybridOrbitOptions options)
    : HybridOrbitProblem(2, {"frequency", "restitution", "wall"}, options) {
  set_parameter("frequency", 2.8);
  set_parameter("restitution", 0.8);
  set_parameter("wall", 0.0);
}

void ImpactOscillator::field(double t, const double* y, const core::Vector& p, double* dy) const {
  dy[0] = y[1];
  dy[1] = -y[0] + std::cos(p[frequency] * t);
}

void ImpactOscillator::field_jacobian(double, const double*, const core::Vector&,
                                      core::Matrix& J) const {
  J.resize(2, 2);
  J << 0, 1, -1, 0;
}

double ImpactOscillator::forcing_period(const core::Vector& p) const {
  return 2 * std::numbers::pi / p[frequency];
}

double ImpactOscillator::event(int, double, const double* y, const core::Vector& p) const {
  return y[0] - p[wall];
}

void ImpactOscillator::reset(int, const double* y, const core::Vector& p, double* y_plus) const {
  y_plus[0] = y[0];
  y_plus[1] = -p[restitution] * y[1];
}

core::FloquetStructure ImpactOscillator::floquet_structure() const {
  return {0, parameters()[restitution] == 1.0 && free_parameter() != restitution};
}

std::optional<PeriodOneOrbit> period_one_orbit(double omega, double r, double sigma) {
  const double pi = std::numbers::pi;
  const double T = 2 * pi / omega;
  if (!(omega > 0) || std::abs(std::remainder(omega, 1.0)) < 1e-12) return std::nullopt;
  const double c = 1 / (1 - omega * omega);  // particular solution c cos(omega t)
  const double alpha = (1 + r) / (2 * std::tan(T / 2));
  const double K = alpha * alpha + (1 - r) * (1 - r) / (4 * omega * omega);
  const double discriminant = alpha * alpha * sigma * sigma - K * (sigma * sigma - c * c);
  if (!(discriminant >= 0)) return std::nullopt;
  const double V = (-alpha * sigma + std::sqrt(discriminant)) / K;
  if (!(V > 0)) return std::nullopt;
  PeriodOneOrbit orbit;
  orbit.impact_velocity = V;
  const double sin_phase = (r - 1) * V / (2 * c * omega);
  const double cos_phase = (sigma + alpha * V) / c;
  orbit.phase = std::atan2(sin_phase, cos_phase);
  if (orbit.phase < 0) orbit.phase += 2 * pi;
  // Free flight from the impact (t* = phase / omega, state (sigma, -r V)) to t = T: the
  // homogeneous part rotates by the elapsed time, the particular one is c cos(omega t).
  const double t_impact = orbit.phase / omega;
  const double a = sigma - c * std::cos(orbit.phase);
  const double u = -r * V + c * omega * std::sin(orbit.phase);
  const double s = T - t_impact;
  orbit.start.resize(2);
  orbit.start << c * std::cos(omega * T) + a * std::cos(s) + u * std::sin(s),
      -c * omega * std::sin(omega * T) - a * std::sin(s) + u * std::cos(s);
  // M ~ S R(T): R the free flight's flow derivative over a period, S the impact's saltation.
  const double acceleration = -sigma + std::cos(orbit.phase);
  core::Matrix R(2, 2), S(2, 2);
  R << std::cos(T), std::sin(T), -std::sin(T), std::cos(T);
  S << -r, 0, (1 + r) * acceleration / V, -r;
  const core::Matrix M = S * R;
  const double trace = M.trace(), det = M.determinant();
  const std::complex<double> root = std::sqrt(std::complex<double>(trace * trace / 4 - det));
  orbit.multipliers = {trace / 2 + root, trace / 2 - root};
  return orbit;
}

double period_doubling_wall(double omega, double r, double lo, double hi) {
  const auto g = [omega, r](double sigma) {
    const auto o = period_one_orbit(omega, r, sigma);
    return o ? std::real((1.0 + o->multipliers[0]) * (1.0 + o->multipliers[1]))
             : std::numeric_limits<double>::quiet_NaN();
  };
  const double g_lo = g(lo);
  if (!(g_lo * g(hi) < 0)) return std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) * g_lo > 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

boost::program_options::options_description scene_keys() {
  namespace po = boost::program_options;
  po::options_description keys(
      "impact_oscillator (x'' + x = cos(omega t), v -> -r v at x = sigma)");
  keys.add_options()  //
      ("frequency", po::value<double>()->default_value(2.8),
       "forcing frequency omega [dimensionless] (> 0, not a whole number)")  //
      ("restitution", po::value<double>()->default_value(0.8),
       "coefficient of restitution r [-] (in (0, 1])")  //
      ("wall", po::value<double>()->default_value(0.0),
       "wall position sigma at the start [dimensionless] (finite)")  //
      ("wall_min", po::value<double>()->default_value(-0.2),
       "stop the branch below this wall position (< wall)")  //
      ("wall_max", po::value<double>()->default_value(1.0),
       "stop the branch above this wall position (> wall; the period-1 orbit grazes before "
       "1 / |1 - omega^2|)")  //
      ("grazing_velocity", po::value<double>()->default_value(4e-3),
       "stop the branch where the impact velocity falls to this (> 0); the grazing orbit "
       "beyond is corrected from there")  //
      ("grazing_gap", po::value<double>()->default_value(1e-3),
       "stop the branch where the orbit's closest approach to the wall between impacts falls to "
       "this (> 0); the grazing orbit beyond is corrected from there")  //
      ("continuation_parameter", po::value<std::string>()->default_value("wall"),
       "the parameter the branch moves: wall, restitution or frequency")  //
      ("rtol", po::value<double>()->default_value(1e-12),
       "CVODE relative tolerance [-] (in (0, 1e-3))");
  return keys;
}

}  // namespace backbone::impact_oscillator
