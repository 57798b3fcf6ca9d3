// TD-BEM against the exact characteristics solver (problems/exact_bar): free vibration over 20
// periods, contact at either end, the bouncing bar, snapshots.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {
namespace {

// Courant number 1 (c dt = L / elements, L / c = 20 dt), u0 and v0 with kinks on the node grid:
// the TD-BEM march is exact at grid instants. Over 20 periods (1600 steps) only round-off
// accumulates, so 1e-12 relative to the amplitude is the claim.
double worst_relative_error(bar::EndType right, ContactMethod method) {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {right, 0};
  const bool free_right = right == bar::EndType::free;
  s.u0 = bar::PiecewiseLinear({0.0, 0.3, 0.55, 1.0}, {0.0, 0.02, -0.01, free_right ? 0.005 : 0.0});
  s.v0 = bar::PiecewiseLinear({0.0, 0.2, 0.45, 1.0}, {0.0, -0.03, 0.01, free_right ? 0.02 : 0.0});
  const double period = free_right ? 4 : 2;
  const int elements = 20;
  const double dt = 1.0 / elements;
  const exact_bar::ExactBarSolution exact(s, 20 * period);
  EXPECT_TRUE(exact.ok());
  TdbemMarch m(s, dt, method);
  double scale = 0, worst = 0;
  const int steps = static_cast<int>(std::lround(20 * period / dt));
  for (int k = 1; k <= steps; ++k) {
    const double t = k * dt;
    m.advance_to(t);
    const double ue = exact.u_end(exact_bar::Side::right, t);
    scale = std::max(scale, std::abs(ue));
    worst = std::max(worst, std::abs(m.end_displacement(true) - ue));
    if (k % 7 == 0)
      for (int i = 0; i <= elements; ++i) {
        const double x = static_cast<double>(i) / elements;
        const double ux = exact.u(x, t);
        scale = std::max(scale, std::abs(ux));
        worst = std::max(worst, std::abs(m.displacement(x) - ux));
      }
  }
  return worst / scale;
}

TEST(TdbemVsExact, FreeVibrationTwentyPeriods) {
  for (auto method : {ContactMethod::event, ContactMethod::projection}) {
    EXPECT_LT(worst_relative_error(bar::EndType::free, method), 1e-12);
    EXPECT_LT(worst_relative_error(bar::EndType::fixed, method), 1e-12);
  }
}

// Mode 1 mirrored to the left end (free right, contact left, u0 = eps (x - L)): checks the
// normal and force sign conventions at x = 0, off the time grid (dt = 0.04: onset 27.5 steps).
TEST(TdbemVsExact, LeftContactEndMatchesExactOffGrid) {
  bar::BarSetup s;
  s.left = {bar::EndType::contact, 1e-3};
  s.right = {bar::EndType::fixed, 0};
  s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.01, 0.0});  // u(0) moves towards the wall at -gap
  const exact_bar::ExactBarSolution exact(s, 10);
  TdbemMarch m(s, 0.04, ContactMethod::event);
  double worst_u = 0, worst_f = 0;
  for (double t = 0.02; t < 10; t += 0.0731) {
    m.advance_to(t);
    worst_u = std::max(worst_u,
                       std::abs(m.end_displacement(false) - exact.u_end(exact_bar::Side::left, t)));
    for (double x : {0.1, 0.5, 0.93})
      worst_u = std::max(worst_u, std::abs(m.displacement(x) - exact.u(x, t)));
  }
  EXPECT_LT(worst_u, 1e-14);
  // Force over a sub-step inside a contact episode equals the exact (constant) force.
  const auto intervals = exact.contact_intervals(exact_bar::Side::left);
  ASSERT_FALSE(intervals.empty());
  TdbemMarch m2(s, 0.04, ContactMethod::event);
  const double mid = 0.5 * (intervals[0].t_close + intervals[0].t_release);
  m2.advance_to(mid);
  worst_f = std::abs(m2.end_force(false) - exact.contact_force(exact_bar::Side::left, mid));
  EXPECT_GT(m2.end_force(false), 0);
  EXPECT_LT(worst_f, 1e-13);
  const auto& ev = m2.events();
  ASSERT_FALSE(ev.empty());
  EXPECT_NEAR(ev[0].t, intervals[0].t_close, 1e-12);
  EXPECT_FALSE(ev[0].right_end);
}

// Bouncing bar: onset (t = 1), impacts of 2L/c and releases all fall on the grid dt = 1/300,
// so the contact-end displacement and the force match the exact solution at grid instants.
TEST(TdbemVsExact, BouncingBarOnTheGrid) {
  bar::BarSetup s;
  s.material = {10.0, 900.0, 1.0, 1.0};
  s.left = {bar::EndType::free, 0};
  s.right = {bar::EndType::contact, 5.0};
  s.body_force = 10;
  const double T = 16.0 / 3;
  const exact_bar::ExactBarSolution exact(s, T);
  for (auto method : {ContactMethod::event, ContactMethod::projection}) {
    TdbemMarch m(s, 1.0 / 300, method);
    double worst_u = 0, worst_f = 0;
    for (int k = 1; k <= 1600; ++k) {
      const double t = k / 300.0;
      m.advance_to(t);
      worst_u = std::max(worst_u, std::abs(m.end_displacement(true) - exact.u_end(t)));
      // TD-BEM force is the mean over the step ending at t; the exact force is linear in t
      // inside an impact (300 -> 500 N): compare with the exact mid-step value.
      if (m.in_contact(true) && exact.in_contact(exact_bar::Side::right, t - 0.5 / 300))
        worst_f =
            std::max(worst_f, std::abs(m.end_force(true) - exact.contact_force(t - 0.5 / 300)));
    }
    EXPECT_LT(worst_u / 5, 1e-11) << to_string(method);
    EXPECT_LT(worst_f / 500, 1e-9) << to_string(method);
  }
}

// Snapshot projections against the exact solver's exact projections (mode 1, half period).
TEST(TdbemVsExact, SnapshotProjectionsMatch) {
  bar::BarSetup s;
  s.right = {bar::EndType::contact, 1e-3};
  s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, -0.01});
  bar::SnapshotRequest r;
  r.dt = 0.013;  // nothing on the grid
  r.elements = 16;
  r.nodal_u = true;
  r.projected_u = true;
  r.projected_v = true;
  const exact_bar::ExactBarSolution exact(s, 3.1);
  for (double t : {1.55, 2.37, 3.1}) {
    const auto a = TdbemSolver(ContactMethod::event).snapshot(s, t, r);
    const auto b = exact.snapshot(t, r);
    ASSERT_TRUE(a.ok);
    for (std::size_t i = 0; i < a.x.size(); ++i) {
      EXPECT_NEAR(a.u[i], b.u[i], 1e-15) << t;
      EXPECT_NEAR(a.u_projected[i], b.u_projected[i], 1e-16) << t;
      EXPECT_NEAR(a.v_projected[i], b.v_projected[i], 1e-16) << t;
    }
  }
}

// The energy diagnostic. Without a body force and after t > L/c it is integrated piece by piece
// from one merge of the two ends' windows (tdbem.cpp, window_energy), before that by quadrature
// over the sorted breakpoints. Both against the exact solution's energy, for a u0 with kinks off
// the grid, v0 = 0, contact episodes and dt off the grid (0.0137): with v0 = 0 the tractions are
// piecewise constant, which the event method reproduces to round-off, so only round-off
// separates the energies (1e-13 relative, for either integration).
// (A v0 with kinks makes them piecewise linear, which no piecewise-constant march holds exactly.)
TEST(TdbemVsExact, EnergyMatchesTheExactEnergyBeforeAndAfterOneTransit) {
  bar::BarSetup s;
  s.right = {bar::EndType::contact, 4e-3};
  s.u0 = bar::PiecewiseLinear({0.0, 0.3, 0.55, 1.0}, {0.0, 0.02, -0.01, 0.003});
  const double t_end = 12;
  const exact_bar::ExactBarSolution exact(s, t_end);
  ASSERT_TRUE(exact.ok());
  TdbemMarch m(s, 0.0137, ContactMethod::event);
  const double e0 = exact.energy(0);
  double worst = 0;
  int closings = 0;
  for (double t = 0.05; t <= t_end; t += 0.0731) {
    m.advance_to(t);
    worst = std::max(worst, std::abs(m.energy() - exact.energy(t)) / e0);
  }
  for (const auto& ev : m.events()) closings += ev.closing ? 1 : 0;
  EXPECT_GT(closings, 2);  // the contact is exercised
  EXPECT_LT(worst, 1e-13);
}

}  // namespace
}  // namespace backbone::contact_bar
