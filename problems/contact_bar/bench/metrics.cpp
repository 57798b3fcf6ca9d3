#include "problems/contact_bar/bench/metrics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/exact_bar/bouncing_bar.hpp"

namespace backbone::contact_bar {

namespace {
const double nan = std::numeric_limits<double>::quiet_NaN();
}

double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() < 2 || y.size() != x.size())
    throw core::InputError("x", fmt::format("a log-log slope needs two or more (x, y) pairs (got "
                                            "{} x and {} y)",
                                            x.size(), y.size()));
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!(x[i] > 0)) throw core::InputError("x", fmt::format("must be > 0 (got {})", x[i]));
    if (!(y[i] > 0)) throw core::InputError("y", fmt::format("must be > 0 (got {})", y[i]));
    const double a = std::log(x[i]), b = std::log(y[i]);
    sx += a, sy += b, sxx += a * a, sxy += a * b;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

double observed_order(double h_coarse, double e_coarse, double h_fine, double e_fine) {
  if (!(e_coarse > 0) || !(e_fine > 0) || std::isnan(h_coarse) || std::isnan(h_fine)) return nan;
  return std::log(e_coarse / e_fine) / std::log(h_coarse / h_fine);
}

ObservedRate observed_rate(const std::vector<double>& errors, double floor) {
  std::size_t used = 0;  // errors[0 .. used - 1] are above the floor
  while (used < errors.size() && errors[used] > floor) ++used;
  ObservedRate rate;
  if (used >= 2)
    rate.ratio = std::pow(errors[used - 1] / errors[0], 1.0 / static_cast<double>(used - 1));
  std::vector<double> orders;
  for (std::size_t k = 1; k + 1 < used; ++k)
    orders.push_back(std::log(errors[k + 1] / errors[k]) / std::log(errors[k] / errors[k - 1]));
  if (!orders.empty()) {
    std::sort(orders.begin(), orders.end());
    const std::size_t h = orders.size() / 2;
    rate.order = orders.size() % 2 ? orders[h] : 0.5 * (orders[h - 1] + orders[h]);
  }
  return rate;
}

double mean_between_breaks(const std::function<double(double)>& f, double a, double b,
                           const std::vector<double>& breaks) {
  a = std::max(a, 0.0);
  if (!(b > a)) return f(std::max(b, 0.0));
  std::vector<double> cuts{a};
  for (double t : breaks)
    if (t > a && t < b) cuts.push_back(t);
  cuts.push_back(b);
  std::sort(cuts.begin() + 1, cuts.end() - 1);
  // Three-point Gauss-Legendre on each piece: exact for quintics, and it never evaluates f at a
  // cut, so no one-sided value is needed. (Simpson with f(r - 1e-12 w) failed there: for a window
  // of width dt = 1e-4 ending on a jump at t = 1.1, r - 1e-12 w rounds back to r, f took the value
  // beyond the jump, and the window mean was off by f / 6: the metric reported a force error of
  // 3.7e-5 for a history that was exact to 3e-14.)
  const double g = std::sqrt(0.6);
  double integral = 0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double mid = 0.5 * (cuts[i] + cuts[i + 1]), half = 0.5 * (cuts[i + 1] - cuts[i]);
    integral += half / 9 * (5 * f(mid - g * half) + 8 * f(mid) + 5 * f(mid + g * half));
  }
  return integral / (b - a);
}

double relative_force_error(const bar::History& h, double dt, ForceWindow window,
                            const std::function<double(double)>& exact,
                            const std::vector<double>& breaks) {
  double num = 0, den = 0;
  for (std::size_t j = 0; j < h.t.size(); ++j) {
    const double t = h.t[j];
    const double mean =
        mean_between_breaks(exact, t - window.before * dt, t + window.after * dt, breaks);
    num += std::abs(h.contact_force[j] - mean);
    den += std::abs(mean);
  }
  return den > 0 ? num / den : nan;
}

std::vector<double> bouncing_bar_force_jumps(double t_end) {
  const double tau = exact_bar::bouncing_bar_setup().material.travel_time();
  std::vector<double> jumps;
  for (double start = 0; start < t_end + 16 * tau; start += 16 * tau)
    for (double s : {3.0, 5.0, 11.0, 13.0}) jumps.push_back(start + s * tau);
  return jumps;
}

Mode1ContactEpisode mode1_contact_episode(const bar::Material& material, double gap,
                                          double energy) {
  const ContactFamily mode1(material, gap, 1);
  const double period = mode1.period(energy);  // NaN below grazing
  const double tau = material.travel_time();
  if (std::isnan(period)) return {nan, nan, nan, nan};
  return {period, period - 2 * tau, 2 * tau, material.axial_stiffness() * mode1.slope(energy)};
}

double residual_unit(ContactBarOrbitProblem& problem, const core::Vector& like) {
  const core::ShootingFormulation kept = problem.formulation();
  problem.set_formulation(core::ShootingFormulation::displacement_periodicity);
  const bar::Material& material = problem.setup_template().material;
  const double gap = problem.setup_template().right.gap;
  core::Vector x = like;  // keeps the knot, if any
  const core::Vector y = problem.node_positions(x);
  const int n = problem.options().elements;
  for (int i = 0; i < n; ++i) x[i] = -0.5 * gap * y[i] / material.length;
  x[problem.period_index()] = 2 * material.travel_time();
  core::Vector r;
  const bool ok = problem.residual(x, r) == core::EvalStatus::ok;
  problem.set_formulation(kept);
  // The last residual entry samples x = L (u0(L) = x[n - 1]) whatever grid the residual uses.
  return ok && r.size() > 0 ? 2 * x[n - 1] / r[r.size() - 1] : nan;
}

double relative_u0_distance(const ContactBarOrbitProblem& problem, const core::Vector& x,
                            const core::Vector& reference) {
  const bar::PiecewiseLinear a = problem.initial_displacement(x);
  const bar::PiecewiseLinear b = problem.initial_displacement(reference);
  double distance = 0, size = 0;
  for (const bar::PiecewiseLinear* f : {&a, &b})
    for (double k : f->knots()) distance = std::max(distance, std::abs(a(k) - b(k)));
  for (double v : b.values()) size = std::max(size, std::abs(v));
  return distance / size;
}

}  // namespace backbone::contact_bar
