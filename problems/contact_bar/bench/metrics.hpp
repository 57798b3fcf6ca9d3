// The measures the contact-bar benchmarks report (problems/contact_bar/bench.hpp): cost
// slopes, observed orders of convergence, the step-averaged contact-force error, the exact
// contact episode of mode 1, and the unit and u0 distance of shooting residuals. Each is a
// plain function of numbers, histories or orbit unknowns, tested on exact oracles
// (tests/problems/contact_bar/test_bench_metrics.cpp).
//
//   double p = log_log_slope(steps, seconds);               // 1: cost linear in the steps
//   double q = observed_order(1e-2, e_coarse, 1e-3, e_fine); // NaN at round-off (error 0)
//   ObservedRate r = observed_rate(newton_residuals, 1e-15); // r.order 2: quadratic
//   const Mode1ContactEpisode m = mode1_contact_episode(material, gap, energy);
//   double f = relative_force_error(history, dt, tdbem_force_window,
//                                   [&](double t) { return m.force_at(t); }, {m.onset, m.release});
//   double metres = residual_unit(orbit_problem, x);          // metres per residual unit
#pragma once

#include <functional>
#include <limits>
#include <vector>

#include "core/types.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"

namespace backbone::contact_bar {

// Least-squares slope of log(y) against log(x): the exponent p of y ~ C x^p. Needs at least two
// points, all positive (InputError "x"/"y" otherwise).
double log_log_slope(const std::vector<double>& x, const std::vector<double>& y);

// Observed order between a coarse and a fine run, log(e_coarse / e_fine) / log(h_coarse /
// h_fine). NaN when either error is not > 0 (zero is round-off: no order to observe) or either
// step is NaN (the first run of a series has no coarser one).
double observed_order(double h_coarse, double e_coarse, double h_fine, double e_fine);

// Observed convergence of an iteration whose errors (or residuals) are e_0, e_1, ...:
// order = median over k of log(e_{k+1} / e_k) / log(e_k / e_{k-1}) (2 quadratic, 1 linear),
// ratio = geometric mean of e_{k+1} / e_k (the linear rate). Only the leading values above
// `floor` (round-off) enter; order needs three of them, ratio two, NaN otherwise.
struct ObservedRate {
  double order = std::numeric_limits<double>::quiet_NaN();
  double ratio = std::numeric_limits<double>::quiet_NaN();
};
ObservedRate observed_rate(const std::vector<double>& errors, double floor);

// Contact forces are impulsive at the step scale, so they are compared as step averages: each
// sample t_n of a method stands for the mean force over the interval its scheme attributes it
// to, [t_n - before dt, t_n + after dt]. TD-BEM: piecewise-constant traction over
// [t_n - dt, t_n]; FEM: the multiplier's impulse lambda_n dt acts over [t_n - dt/2, t_n + dt/2].
struct ForceWindow {
  double before = 1;
  double after = 0;
};
inline constexpr ForceWindow tdbem_force_window{1, 0};
inline constexpr ForceWindow fem_force_window{0.5, 0.5};

// Mean of f over [a, b] (a clipped to 0), f smooth between the jumps listed in `breaks`:
// three-point Gauss on each piece (f is never evaluated at a cut), so exact for f piecewise
// quintic, also when a jump sits on a window end far from t = 0. b <= a: f(max(b, 0)).
double mean_between_breaks(const std::function<double(double)>& f, double a, double b,
                           const std::vector<double>& breaks);

// Relative L1 error of the step-averaged contact force of history h (time step dt, samples
// attributed by `window`) against the exact force `exact` (jumps at `breaks`):
// sum_n |F_n - mean(exact over window n)| / sum_n |mean(exact over window n)|.
// 0 when the history holds the exact window means; NaN when the exact force is 0 throughout.
double relative_force_error(const bar::History& h, double dt, ForceWindow window,
                            const std::function<double(double)>& exact,
                            const std::vector<double>& breaks);

// Times in [0, t_end + one period] where the contact force of the closed-form bouncing bar
// (problems/exact_bar/bouncing_bar.hpp, tau = L/c) jumps: each period of 16 tau has two impacts
// of 2 tau, starting at 3 tau and 11 tau. The `breaks` of relative_force_error for that scene.
std::vector<double> bouncing_bar_force_jumps(double t_end);

// The contact episode of the exact mode 1 (u0 = eps x, v0 = 0, problems/contact_bar/README.md)
// at energy E, from ContactFamily: period T, contact on [onset, release) = [T - 2L/c, 2L/c)
// (the end reaches the wall after (L + g0/|eps|)/c and leaves it when the reflected front
// returns) with constant force EA |eps|, |eps| = ContactFamily::slope(E). Fields are NaN below
// grazing.
struct Mode1ContactEpisode {
  double period;
  double onset;
  double release;
  double force;
  double force_at(double t) const { return t >= onset && t < release ? force : 0.0; }
};
Mode1ContactEpisode mode1_contact_episode(const bar::Material& material, double gap, double energy);

// Metres per unit of the problem's shooting residual, measured rather than assumed (a problem
// may scale its residual, e.g. by g0): the paper residual u0 - u(T) of the linear state
// u0 = -g0 x / (2L) at T = 2L/c is exactly 2 u0, because every fixed-free linear motion
// satisfies u(t + 2L/c) = -u(t) and an end amplitude g0/2 never reaches the wall. `like`
// supplies the layout (its free knot, if any, is kept). The problem's formulation is restored.
// NaN when the residual fails.
double residual_unit(ContactBarOrbitProblem& problem, const core::Vector& like);

// max_x |u0(x) - u0*(x)| / max_x |u0*(x)| between the piecewise-linear u0 of two points of the
// problem (exact: the difference is piecewise linear, so its maximum sits on a knot of either).
double relative_u0_distance(const ContactBarOrbitProblem& problem, const core::Vector& x,
                            const core::Vector& reference);

}  // namespace backbone::contact_bar
