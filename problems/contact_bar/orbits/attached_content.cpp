#include "problems/contact_bar/orbits/attached_content.hpp"

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <numeric>
#include <unsupported/Eigen/FFT>
#include <vector>

namespace backbone::contact_bar {

namespace {

// End displacement at samples instants k T / samples, k = 0..samples - 1, of the orbit x.
std::vector<double> end_displacement(const ContactBarOrbitProblem& problem, const core::Vector& x,
                                     const bar::BarSolver& solver, int samples) {
  const double period = x[problem.period_index()];
  bar::SimulationOptions options;
  options.t_end = period;
  options.dt = period / samples;
  options.history_samples = samples + 1;
  options.energy = false;
  options.elements = problem.state_size();
  const bar::History h = solver.simulate(problem.setup_at(x), options);
  std::vector<double> u(h.u_contact.begin(), h.u_contact.end());
  if (static_cast<int>(u.size()) == samples + 1) u.pop_back();
  return u;
}

// The content wavenumber of the attached u0 against the branch's (the header): the cosine
// coefficients c_n = (2/L) int (|u0_a'| / s - 1) cos(n pi x / L) dx, n = 1..2N, exact for the
// piecewise-constant slope, s the branch orbit's mean |u0'|.
int content_wavenumber(const bar::PiecewiseLinear& branch, const bar::PiecewiseLinear& attached,
                       double length, int harmonics) {
  const auto& xb = branch.knots();
  double s = 0;
  for (std::size_t i = 1; i < xb.size(); ++i)
    s += std::abs(branch.values()[i] - branch.values()[i - 1]);
  s /= length;
  if (!(s > 0)) return 0;
  const auto& xa = attached.knots();
  const auto& ya = attached.values();
  std::vector<double> c(static_cast<std::size_t>(harmonics) + 1, 0.0);
  double largest = 0;
  for (int n = 1; n <= harmonics; ++n) {
    const double k = n * std::numbers::pi / length;
    double sum = 0;
    for (std::size_t i = 1; i < xa.size(); ++i) {
      const double phi = std::abs((ya[i] - ya[i - 1]) / (xa[i] - xa[i - 1])) / s - 1;
      sum += phi * (std::sin(k * xa[i]) - std::sin(k * xa[i - 1])) / k;
    }
    c[static_cast<std::size_t>(n)] = 2 * sum / length;
    largest = std::max(largest, std::abs(c[static_cast<std::size_t>(n)]));
  }
  if (!(largest > 0)) return 0;
  int p = 0;
  for (int n = 1; n <= harmonics; ++n)
    if (std::abs(c[static_cast<std::size_t>(n)]) >= 1e-3 * largest) p = std::gcd(p, n);
  return p;
}

}  // namespace

AttachedContent attached_content(const ContactBarOrbitProblem& problem,
                                 const core::Vector& on_branch, const core::Vector& attached,
                                 const bar::BarSolver& solver, int samples) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  AttachedContent c{nan, nan, nan, nan, nan};
  const std::vector<double> base = end_displacement(problem, on_branch, solver, samples);
  const std::vector<double> other = end_displacement(problem, attached, solver, samples);
  if (static_cast<int>(base.size()) != samples || other.size() != base.size()) return c;
  std::vector<double> d(base.size());
  double mean = 0;
  for (std::size_t k = 0; k < d.size(); ++k) {
    d[k] = other[k] - base[k];
    mean += d[k] / static_cast<double>(d.size());
  }
  double amplitude = 0;
  for (double& v : d) {
    v -= mean;
    amplitude = std::max(amplitude, std::abs(v));
  }
  if (!std::isfinite(amplitude)) return c;
  c.amplitude = amplitude;
  // Spectrum over one period (both orbits are sampled on their own period, so the content is
  // periodic over the sampled window): harmonics 1..samples/2 by an FFT (Eigen's, kissfft),
  // O(samples log samples), so describing a branch point costs little beside locating it.
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, d);
  int best = 0;
  double best_magnitude = -1;
  for (int h = 1; h <= samples / 2; ++h) {
    const double magnitude = std::abs(spectrum[static_cast<std::size_t>(h)]);
    if (magnitude > best_magnitude) {
      best_magnitude = magnitude;
      best = h;
    }
  }
  c.frequency_ratio = best;
  int crossings = 0;
  for (std::size_t k = 0; k < d.size(); ++k) {
    const double a = d[k], b = d[(k + 1) % d.size()];
    if ((a < 0 && b >= 0) || (a >= 0 && b < 0)) ++crossings;
  }
  c.oscillations_per_period = 0.5 * crossings;
  const double length = problem.setup_template().material.length;
  const int p = content_wavenumber(problem.initial_displacement(on_branch),
                                   problem.initial_displacement(attached), length,
                                   2 * problem.options().elements);
  c.content_wavenumber = p > 0 ? p : nan;
  c.resonance_order = p > 0 ? p * on_branch[problem.period_index()] *
                                  problem.setup_template().material.wave_speed() / (2 * length)
                            : nan;
  return c;
}

}  // namespace backbone::contact_bar
