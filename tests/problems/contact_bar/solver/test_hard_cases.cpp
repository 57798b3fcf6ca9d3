// Hard cases of the TD-BEM contact bar (problems/contact_bar/solver/README.md, section 'Hard
// cases'): each with its expectation and an independent oracle (the exact characteristics solver of
// problems/exact_bar, the closed forms of family.hpp). Every case either meets a stated error or
// stops with a status; none may hang, crash or return NaN silently.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/bouncing_bar.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {
namespace {

// The paper's bar (E = rho = L = A = 1, c = 1), fixed at 0, wall at `gap` beyond x = L, started
// on the exact mode 1 u0 = eps x (problems/contact_bar/orbits/README.md, section 'Mode 1').
bar::BarSetup mode1_setup(double gap, double eps) {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, gap};
  s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, eps});
  return s;
}

// max_x |u(x, t) - eps x| / |eps| after marching to t (101 points).
double return_error(TdbemMarch& m, double t, double eps) {
  EXPECT_TRUE(m.advance_to(t));
  double worst = 0;
  for (int i = 0; i <= 100; ++i)
    worst = std::max(worst, std::abs(m.displacement(i / 100.0) - eps * i / 100.0));
  return worst / std::abs(eps);
}

// Grazing: end amplitude (1 + 1e-9) g0, a contact of 2e-9 s inside one step of 0.013 s; and
// exactly g0, a grazing instant. Mode 1 is piecewise linear, which the event method holds to
// round-off at any dt: back to u0 after the closed-form period within 1e-12.
TEST(HardCases, GrazingOrbitsReturnToTheirStart) {
  const double gap = 1e-3;
  for (double amplitude : {1 + 1e-9, 1.0}) {
    const double eps = -gap * amplitude;
    const ContactFamily mode1({1, 1, 1, 1}, gap, 1);
    const double period = 3 + gap / std::abs(eps);  // = mode1.period(E) above grazing
    if (amplitude > 1) {
      EXPECT_NEAR(mode1.period(0.5 * eps * eps), period, 1e-12);
    }
    TdbemMarch m(mode1_setup(gap, eps), 0.013, ContactMethod::event);
    EXPECT_LT(return_error(m, period, eps), 1e-12) << amplitude;
    EXPECT_NEAR(m.energy(), 0.5 * eps * eps, 1e-12 * 0.5 * eps * eps) << amplitude;
  }
}

// High energy: T - 3L/c = g0 / |eps| = 1e-4 s, ten times below dt = 1e-3 (the contact-free
// part of the period is shorter than one step). Exact to round-off as above: 1e-12.
TEST(HardCases, ContactFreePartShorterThanAStep) {
  const double gap = 1e-3, eps = -10.0;
  const double period = 3 + gap / std::abs(eps);
  TdbemMarch m(mode1_setup(gap, eps), 1e-3, ContactMethod::event);
  EXPECT_LT(return_error(m, period, eps), 1e-12);
  EXPECT_LT(return_error(m, 2 * period, eps), 1e-12);
}

// Gap -> 0 (1e-12 and 0) and a bar that starts on the wall (u0(L) = g0 with a compressive
// strain: the subharmonic member of problems/contact_bar/orbits/README.md 'Subharmonic continuum'
// at shape 0.3). Oracle: the exact solver, u(L, t) over two of its periods, relative to max |u0|
// (1e-12).
TEST(HardCases, VanishingGapAndStartInContactMatchTheExactSolver) {
  std::vector<std::pair<bar::BarSetup, double>> cases;
  cases.emplace_back(mode1_setup(1e-12, -0.01), 3.0);
  cases.emplace_back(mode1_setup(0.0, -0.01), 3.0);
  const SubharmonicMember member = subharmonic_member({1, 1, 1, 1}, 1e-3, 1.25e-5, 0.3);
  bar::BarSetup on_wall = mode1_setup(1e-3, -0.01);
  on_wall.u0 = member.u0;
  cases.emplace_back(on_wall, member.period);
  for (const auto& [s, period] : cases) {
    const exact_bar::ExactBarSolution exact(s, 2 * period);
    ASSERT_TRUE(exact.ok());
    double scale = 0;
    for (double v : s.u0.values()) scale = std::max(scale, std::abs(v));
    TdbemMarch m(s, 0.0123, ContactMethod::event);
    double worst = 0;
    for (double t = 0.05; t <= 2 * period; t += 0.0977) {
      ASSERT_TRUE(m.advance_to(t));
      worst = std::max(worst, std::abs(m.end_displacement(true) - exact.u_end(t)));
    }
    EXPECT_LT(worst / scale, 1e-12) << "gap " << s.right.gap;
  }
}

// Courant numbers c dt / dx other than 1 (dx = L / 100): the event method does not depend on
// the node grid; mode 1 with the onset off the grid returns within 1e-12.
TEST(HardCases, CourantNumbersOtherThanOne) {
  const double gap = 1.23456789e-3, eps = -0.01;
  for (double courant : {0.37, 0.999, 1.7, 23.0, 100.0}) {
    TdbemMarch m(mode1_setup(gap, eps), courant / 100, ContactMethod::event);
    EXPECT_LT(return_error(m, 3 + gap / std::abs(eps), eps), 1e-12) << courant;
  }
}

// 10^4 periods of mode 1, the paper scene (dt = 0.01). Mode 1 is piecewise linear with every
// kink on a grid point, and the march holds it to round-off for ever
// (problems/contact_bar/solver/README.md 'Hard cases': step-grid times, round-off closings held
// where they are, Q re-gauged): after 10^4 periods the energy, u(L) and the projected u (relative
// to its largest entry) are the start's, and half a period later u(L) is a fresh march's. Bounds
// 1e-13 relative: above round-off, and orders of magnitude below what a drift of the march would
// leave.
TEST(HardCases, TenThousandPeriodsOfModeOne) {
  const double gap = 1e-3, eps = -0.01, period = 3.1;
  const bar::BarSetup s = mode1_setup(gap, eps);
  TdbemMarch m(s, 0.01, ContactMethod::event);
  const std::vector<double> start = m.projected_displacement(100);
  ASSERT_TRUE(m.advance_to(1e4 * period));
  const double e0 = 0.5 * eps * eps;
  EXPECT_LT(std::abs(m.energy() / e0 - 1), 1e-13);
  EXPECT_LT(std::abs(m.end_displacement(true) - eps), 1e-13 * std::abs(eps));
  const std::vector<double> back = m.projected_displacement(100);
  double worst = 0, scale = 0;
  for (std::size_t i = 0; i < start.size(); ++i) {
    worst = std::max(worst, std::abs(back[i] - start[i]));
    scale = std::max(scale, std::abs(start[i]));
  }
  EXPECT_LT(worst, 1e-13 * scale);
  EXPECT_EQ(m.events().size(), 2u * 10000u);  // one closing, one release per period
  EXPECT_LE(m.stored_knots(), 210u);          // no echo clusters: the window of 2 x 101 knots
  // Half a period on (t = 1.55: in contact), against a fresh march to 1.55.
  TdbemMarch fresh(s, 0.01, ContactMethod::event);
  ASSERT_TRUE(fresh.advance_to(0.5 * period));
  ASSERT_TRUE(m.advance_to(1e4 * period + 0.5 * period));
  EXPECT_NEAR(m.end_displacement(true), fresh.end_displacement(true), 1e-13 * std::abs(eps));
  EXPECT_NEAR(m.end_force(true), fresh.end_force(true), 1e-13 * std::abs(eps));
}

// Free vibration, 10^4 periods: the bar fixed at both ends from a hat u0 (peak 0.01 at x = 0.3,
// kinks off the step grid's lattice of 0.01: echoes at 0.3 + k), period 2 L/c; and fixed-free
// from u0 = -0.01 x with a knot at 0.37 (period 4 L/c; u(L) moves). No contact: the march is
// linear and exact to round-off: after 10^4 periods the energy, u(L) and the projected u are
// the start's. Bounds 1e-13 relative, as above.
TEST(HardCases, TenThousandPeriodsOfFreeVibration) {
  bar::BarSetup fixed_fixed;
  fixed_fixed.left = {bar::EndType::fixed, 0};
  fixed_fixed.right = {bar::EndType::fixed, 0};
  fixed_fixed.u0 = bar::PiecewiseLinear({0.0, 0.3, 1.0}, {0.0, 0.01, 0.0});
  bar::BarSetup fixed_free;
  fixed_free.left = {bar::EndType::fixed, 0};
  fixed_free.right = {bar::EndType::free, 0};
  fixed_free.u0 = bar::PiecewiseLinear({0.0, 0.37, 1.0}, {0.0, 0.004, -0.01});
  for (const auto& [s, period] : {std::pair{fixed_fixed, 2.0}, std::pair{fixed_free, 4.0}}) {
    TdbemMarch m(s, 0.01, ContactMethod::event);
    const double e0 = m.energy();
    const std::vector<double> start = m.projected_displacement(100);
    ASSERT_TRUE(m.advance_to(1e4 * period));
    EXPECT_LT(std::abs(m.energy() / e0 - 1), 1e-13) << period;
    EXPECT_LT(std::abs(m.end_displacement(true) - s.u0(1.0)), 1e-13 * 0.01) << period;
    const std::vector<double> back = m.projected_displacement(100);
    double worst = 0, scale = 0;
    for (std::size_t i = 0; i < start.size(); ++i) {
      worst = std::max(worst, std::abs(back[i] - start[i]));
      scale = std::max(scale, std::abs(start[i]));
    }
    EXPECT_LT(worst, 1e-13 * scale) << period;
  }
}

// Chattering after projection: the bouncing bar (problems/exact_bar/README.md) has a second
// impact; the projection method (first order) may chatter there. Over two periods it must stay
// finite and converge at first order to the exact contact-end displacement: halving dt from
// T / (1000 sqrt 2) (impacts off the grid; on it projection is exact) must cut the worst error
// by at least 1.5x (first order: 2x); the energy error (in units of the potential drop
// b A L g0 of the fall) likewise.
TEST(HardCases, ProjectionAfterTheSecondImpactConverges) {
  const bar::BarSetup s = exact_bar::bouncing_bar_setup();
  const double period = exact_bar::bouncing_bar_period();
  const exact_bar::ExactBarSolution exact(s, 2 * period);
  const double energy_scale = s.body_force * s.material.area * s.material.length * s.right.gap;
  double worst[2] = {0, 0}, worst_energy[2] = {0, 0};
  for (int level = 0; level < 2; ++level) {
    const int steps = static_cast<int>(std::lround(1000 * std::sqrt(2.0))) << level;
    const double dt = period / steps;
    TdbemMarch m(s, dt, ContactMethod::projection);
    for (int k = 1; k <= 2 * steps; ++k) {
      const double t = k * dt;
      ASSERT_TRUE(m.advance_to(t));
      worst[level] = std::max(worst[level], std::abs(m.end_displacement(true) - exact.u_end(t)));
      if (k % 50 == 0)
        worst_energy[level] =
            std::max(worst_energy[level], std::abs(m.energy() - exact.energy(t)) / energy_scale);
    }
    EXPECT_TRUE(std::isfinite(worst[level]) && std::isfinite(worst_energy[level]));
  }
  RecordProperty("u_error_dt", std::to_string(worst[0] / s.right.gap));
  RecordProperty("u_error_dt_half", std::to_string(worst[1] / s.right.gap));
  EXPECT_LT(worst[1], worst[0] / 1.5);
  EXPECT_LT(worst_energy[1], worst_energy[0] / 1.5);
}

// n >= 10^6 steps: 10^6 steps of mode 1 at dt = 1e-4 through simulate (two rows; u(L) against
// the exact solver within 1e-12 m, round-off), and N = 1000: the exact projections of v and u on
// 1000 elements (what a shooting residual reads) against the exact solver's, relative to their
// largest entry (1e-12, round-off).
TEST(HardCases, AMillionStepsAndAThousandElements) {
  const double gap = 1e-3, eps = -0.01;
  const bar::BarSetup s = mode1_setup(gap, eps);
  bar::SimulationOptions o;
  o.dt = 1e-4;
  o.t_end = 1e6 * o.dt;  // 100 s: 32.26 periods
  o.history_samples = 2;
  const bar::History h = TdbemSolver(ContactMethod::event).simulate(s, o);
  ASSERT_EQ(h.t.size(), 2u);
  EXPECT_NEAR(h.t.back(), o.t_end, 1e-9);
  const exact_bar::ExactBarSolution exact(s, o.t_end);
  EXPECT_NEAR(h.u_contact.back(), exact.u_end(o.t_end), 1e-12);
  // Energy: its error is set in the first L/c and carried unchanged after: the initial-condition
  // term reads u0 at L - c t, a position rounded to ulp(L), and over a step of 1e-4 s that is a
  // slope (velocity) error of eps ulp(L) / (c dt) ~ 5e-13 relative near x = L. Bound 1e-12
  // relative.
  EXPECT_NEAR(h.energy.back(), 0.5 * eps * eps, 1e-12 * 0.5 * eps * eps);

  bar::SnapshotRequest r;
  r.dt = 3.1 / 40;
  r.elements = 1000;
  r.projected_u = true;
  r.projected_v = true;
  // t = 1.3: inside the contact, v and u both nonzero (at T/2 = 1.55, v = 0).
  const bar::FieldSnapshot a = TdbemSolver(ContactMethod::event).snapshot(s, 1.3, r);
  const bar::FieldSnapshot b = exact_bar::ExactBarSolver().snapshot(s, 1.3, r);
  ASSERT_TRUE(a.ok) << a.message;
  ASSERT_TRUE(b.ok) << b.message;
  for (const auto& [ta, tb] :
       {std::pair{&a.v_projected, &b.v_projected}, std::pair{&a.u_projected, &b.u_projected}}) {
    ASSERT_EQ(ta->size(), 1001u);
    double worst = 0, scale = 0;
    for (std::size_t i = 0; i < ta->size(); ++i) {
      worst = std::max(worst, std::abs((*ta)[i] - (*tb)[i]));
      scale = std::max(scale, std::abs((*tb)[i]));
    }
    EXPECT_LT(worst, 1e-12 * scale);
  }
}

}  // namespace
}  // namespace backbone::contact_bar
