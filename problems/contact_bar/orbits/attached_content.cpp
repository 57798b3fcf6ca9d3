#include "problems/contact_bar/orbits/attached_content.hpp"

#include <cmath>
#include <complex>
#include <limits>
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

}  // namespace

AttachedContent attached_content(const ContactBarOrbitProblem& problem,
                                 const core::Vector& on_branch, const core::Vector& attached,
                                 const bar::BarSolver& solver, int samples) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  AttachedContent c{nan, nan, nan};
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
  return c;
}

}  // namespace backbone::contact_bar
