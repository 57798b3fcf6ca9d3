// The benchmark metrics of problems/contact_bar/bench/metrics.hpp on exact oracles: power laws
// of known exponent, step means computed by hand, the closed-form bouncing bar and mode 1
// (against the exact characteristics solver), and the residual scale the problem documents.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/errors.hpp"
#include "problems/contact_bar/bench/metrics.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/exact_bar/bouncing_bar.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"

namespace {

using namespace backbone;
using namespace backbone::contact_bar;

TEST(BenchMetrics, LogLogSlopeOfAPowerLawIsItsExponent) {
  std::vector<double> x, y;
  for (double n : {1e3, 1e4, 1e5, 1e6}) x.push_back(n), y.push_back(3e-7 * std::pow(n, 1.7));
  // Exact data: only the rounding of log() (1e-16 relative on logs of size 10) remains.
  EXPECT_NEAR(log_log_slope(x, y), 1.7, 1e-12);
  EXPECT_THROW(log_log_slope({1.0}, {1.0}), core::InputError);
  EXPECT_THROW(log_log_slope({1.0, 0.0}, {1.0, 2.0}), core::InputError);
}

TEST(BenchMetrics, ObservedOrderOfAPowerLaw) {
  const auto error = [](double h) { return 2.5 * std::pow(h, 1.5); };
  EXPECT_NEAR(observed_order(1e-2, error(1e-2), 1e-3, error(1e-3)), 1.5, 1e-12);
  EXPECT_NEAR(observed_order(0.1, error(0.1), 0.1 / std::sqrt(2.0), error(0.1 / std::sqrt(2.0))),
              1.5, 1e-12);
  // An error at round-off (0) or the first run of a series (no coarser h) has no order.
  EXPECT_TRUE(std::isnan(observed_order(1e-2, 0.0, 1e-3, error(1e-3))));
  EXPECT_TRUE(std::isnan(observed_order(1e-2, error(1e-2), 1e-3, 0.0)));
  EXPECT_TRUE(std::isnan(observed_order(std::nan(""), std::nan(""), 1e-3, error(1e-3))));
}

TEST(BenchMetrics, ObservedRateTellsQuadraticFromLinear) {
  // e_k = 10^(-2^k): quadratic (order 2); the last value is below the floor and is left out.
  const ObservedRate quadratic = observed_rate({1e-1, 1e-2, 1e-4, 1e-8, 1e-16}, 1e-15);
  EXPECT_NEAR(quadratic.order, 2.0, 1e-12);
  EXPECT_NEAR(quadratic.ratio, std::pow(1e-7, 1.0 / 3.0), 1e-15);
  // e_k = 0.3^k: linear, rate 0.3.
  std::vector<double> e;
  for (int k = 0; k < 10; ++k) e.push_back(std::pow(0.3, k));
  const ObservedRate linear = observed_rate(e, 0.0);
  EXPECT_NEAR(linear.order, 1.0, 1e-12);
  EXPECT_NEAR(linear.ratio, 0.3, 1e-14);
  // Two values above the floor: a ratio, no order; one value: neither.
  const ObservedRate two = observed_rate({1e-2, 1e-4, 1e-20}, 1e-15);
  EXPECT_NEAR(two.ratio, 1e-2, 1e-16);
  EXPECT_TRUE(std::isnan(two.order));
  EXPECT_TRUE(std::isnan(observed_rate({1e-2}, 1e-15).ratio));
}

TEST(BenchMetrics, MeanBetweenBreaksIsExactForPiecewiseCubics) {
  // t^3 below 1, 5 + t^2 from 1 on: mean over [0.5, 2] by hand.
  const auto f = [](double t) { return t < 1 ? t * t * t : 5 + t * t; };
  const double exact = ((1 - std::pow(0.5, 4)) / 4 + 5 + (8 - 1) / 3.0) / 1.5;
  // Three-point Gauss is exact on each cubic piece: only round-off (a few ulps) remains.
  EXPECT_NEAR(mean_between_breaks(f, 0.5, 2.0, {1.0}), exact, 1e-14 * exact);
  // The window is clipped at t = 0; an empty window is the value at its end.
  EXPECT_NEAR(mean_between_breaks(f, -1.0, 1.0, {1.0}), 0.25, 1e-14);
  EXPECT_DOUBLE_EQ(mean_between_breaks(f, 2.0, 2.0, {1.0}), 9.0);
}

// A narrow window that ends on a jump far from t = 0 (the step of dt = 1e-4 ending at the mode-1
// onset 1.1, results/bench/mode1_convergence): the mean is that of the side inside the window,
// 0 here, exactly. The former Simpson rule sampled f at r - 1e-12 w, which rounds back to r when
// w = 1e-4 and r = 1.1, and returned f / 6.
TEST(BenchMetrics, MeanBetweenBreaksTakesTheInsideOfANarrowWindowAtAJump) {
  const double onset = 1.1;
  const auto f = [&](double t) { return t >= onset ? 0.01 : 0.0; };
  for (double dt : {1e-2, 1e-4, 1e-6, 1e-9}) {
    EXPECT_EQ(mean_between_breaks(f, onset - dt, onset, {onset}), 0.0) << dt;
    EXPECT_NEAR(mean_between_breaks(f, onset, onset + dt, {onset}), 0.01, 1e-15) << dt;
  }
}

// The exact mean of a force `level` on [onset, release) over [a, b], by interval overlap.
double window_mean(double level, double onset, double release, double a, double b) {
  const double overlap = std::max(0.0, std::min(b, release) - std::max(a, onset));
  return level * overlap / (b - a);
}

TEST(BenchMetrics, ForceErrorIsZeroOnTheExactStepMeansAndKnownWhenShifted) {
  const double onset = 1.1, release = 2.0, level = 0.01, dt = 0.1;
  const auto exact = [&](double t) { return t >= onset && t < release ? level : 0.0; };
  bar::History exact_means, scaled, late;
  for (int j = 1; j <= 31; ++j) {
    const double t = j * dt;
    exact_means.t.push_back(t);
    exact_means.contact_force.push_back(window_mean(level, onset, release, t - dt, t));
  }
  scaled = exact_means;
  for (double& f : scaled.contact_force) f *= 1.1;
  // One step late: sample j holds the mean of window j - 1. The 9 full windows ending at 1.2 ..
  // 2.0 lose the first and gain one after 2.0: |error| 2 level over a total of 9 level.
  late = exact_means;
  for (std::size_t j = late.t.size() - 1; j > 0; --j)
    late.contact_force[j] = late.contact_force[j - 1];
  late.contact_force[0] = 0;
  const std::vector<double> breaks{onset, release};
  // Tolerances: the window ends fall on the breaks up to the rounding of j * dt (1e-16), and
  // the one-sided samples sit 1e-12 of a piece inside it.
  EXPECT_NEAR(relative_force_error(exact_means, dt, tdbem_force_window, exact, breaks), 0.0, 1e-10);
  EXPECT_NEAR(relative_force_error(scaled, dt, tdbem_force_window, exact, breaks), 0.1, 1e-10);
  EXPECT_NEAR(relative_force_error(late, dt, tdbem_force_window, exact, breaks), 2.0 / 9.0, 1e-10);
  // The FEM window is centred: a sample at the onset stands for half the force.
  EXPECT_NEAR(mean_between_breaks(exact, onset - fem_force_window.before * dt,
                                  onset + fem_force_window.after * dt, breaks),
              0.5 * level, 1e-12 * level);
}

TEST(BenchMetrics, BouncingBarForceJumpsAreWhereTheClosedFormJumps) {
  const double period = exact_bar::bouncing_bar_period();
  const std::vector<double> jumps = bouncing_bar_force_jumps(2 * period);
  ASSERT_GE(jumps.size(), 8u);
  // tau = 1/3: impacts on [1, 5/3) and [11/3, 13/3) in each period of 16/3.
  EXPECT_NEAR(jumps[0], 1.0, 1e-14);
  EXPECT_NEAR(jumps[3], 13.0 / 3.0, 1e-14);
  EXPECT_NEAR(jumps[4], period + 1.0, 1e-13);
  const double delta = 1e-9;
  for (std::size_t k = 0; k < jumps.size(); ++k) {
    const double t = jumps[k];
    // The force jumps by 300 N or 500 N across each listed time ...
    EXPECT_GT(std::abs(exact_bar::bouncing_bar_contact_force(t + delta) -
                       exact_bar::bouncing_bar_contact_force(t - delta)),
              100.0)
        << "t = " << t;
    // ... and is continuous (slope rho A c g = 9000 N/s) half way to the next one.
    if (k + 1 < jumps.size()) {
      const double m = 0.5 * (t + jumps[k + 1]);
      EXPECT_LT(std::abs(exact_bar::bouncing_bar_contact_force(m + delta) -
                         exact_bar::bouncing_bar_contact_force(m - delta)),
                1e-4);
    }
  }
}

TEST(BenchMetrics, Mode1ContactEpisodeOfThePaperScene) {
  const bar::Material paper;  // E = rho = L = A = 1
  // eps = -0.01: E = eps^2 / 2; T = 3 + g0 / |eps| = 3.1, contact on [1.1, 2) at 0.01 N.
  const Mode1ContactEpisode m = mode1_contact_episode(paper, 1e-3, 0.5e-4);
  EXPECT_NEAR(m.period, 3.1, 1e-14);
  EXPECT_NEAR(m.onset, 1.1, 1e-14);
  EXPECT_NEAR(m.release, 2.0, 1e-14);
  EXPECT_NEAR(m.force, 0.01, 1e-16);
  EXPECT_DOUBLE_EQ(m.force_at(1.5), m.force);
  EXPECT_EQ(m.force_at(2.0), 0.0);
  // Below grazing (|eps| L < g0) there is no contact.
  EXPECT_TRUE(std::isnan(mode1_contact_episode(paper, 1e-3, 0.4e-6).onset));
}

TEST(BenchMetrics, Mode1ContactEpisodeIsTheExactSolversContact) {
  // A steel bar (c ~ 5172 m/s): the exact characteristics solver's contact force on u0 = eps x.
  bar::BarSetup s;
  s.material = {2.5, 2.1e11, 7850, 3e-4};
  const double gap = 1e-4, eps = -2.7 * gap / s.material.length;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, gap};
  s.u0 = bar::PiecewiseLinear({0.0, s.material.length}, {0.0, eps * s.material.length});
  const double energy = 0.5 * s.material.axial_stiffness() * s.material.length * eps * eps;
  const Mode1ContactEpisode m = mode1_contact_episode(s.material, gap, energy);
  bar::SimulationOptions o;
  o.t_end = m.period;
  o.dt = m.period / 2000;
  o.history_samples = 2002;
  o.energy = false;
  const bar::History h = exact_bar::ExactBarSolver().simulate(s, o);
  ASSERT_GT(h.t.size(), 1000u);
  int in_contact = 0;
  for (std::size_t j = 0; j < h.t.size(); ++j) {
    const double t = h.t[j];
    if (std::abs(t - m.onset) < o.dt || std::abs(t - m.release) < o.dt) continue;  // at a jump
    // Exact solver on piecewise-linear data: round-off only (1e-9 of the force).
    EXPECT_NEAR(h.contact_force[j], m.force_at(t), 1e-9 * m.force) << "t = " << t;
    in_contact += m.force_at(t) > 0;
  }
  EXPECT_GT(in_contact, 100);
}

TEST(BenchMetrics, ResidualUnitIsTheGapTheProblemScalesBy) {
  // The orbit problem documents its residual in units of g0 (displacement_scale): the
  // metres per residual unit the metric finds must be that, whatever the formulation, mode and
  // bar.
  bar::BarSetup s;
  s.material = {2.0, 3.0, 1.5, 0.5};
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 2e-3};
  const exact_bar::ExactBarSolver exact;
  for (int mode : {1, 2}) {
    OrbitOptions o;
    o.elements = 12;
    o.free_knots = mode == 2 ? 1 : 0;
    o.test_elements = 2 * (o.elements + o.free_knots);
    o.steps_per_period = 40;
    ContactBarOrbitProblem problem(s, exact, o);
    for (auto formulation : {core::ShootingFormulation::half_period_velocity,
                             core::ShootingFormulation::displacement_periodicity}) {
      problem.set_formulation(formulation);
      const core::Vector x = problem.contact_family_guess(mode, 3.0);
      // Exact solver, linear motion: round-off only.
      EXPECT_NEAR(residual_unit(problem, x), problem.displacement_scale(), 1e-12 * 2e-3);
      EXPECT_EQ(problem.formulation(), formulation);  // restored
    }
  }
}

TEST(BenchMetrics, RelativeU0DistanceOfAScaledOrbit) {
  bar::BarSetup s;
  s.right = {bar::EndType::contact, 1e-3};
  const exact_bar::ExactBarSolver exact;
  OrbitOptions o;
  o.elements = 10;
  const ContactBarOrbitProblem problem(s, exact, o);
  const core::Vector x = problem.contact_family_guess(1, 4.0);
  core::Vector y = x;
  for (int i = 0; i < o.elements; ++i) y[i] *= 1.02;
  EXPECT_EQ(relative_u0_distance(problem, x, x), 0.0);
  EXPECT_NEAR(relative_u0_distance(problem, y, x), 0.02, 1e-14);
}

}  // namespace
