// A bar end in a clearance (two walls, Signorini on both): the TD-BEM and the FEM against the
// exact characteristics solver, on data that is no orbit, so that both walls are hit at
// instants off every time grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_solution.hpp"
#include "problems/fem_bar/fem.hpp"

namespace backbone::contact_bar {
namespace {

// Fixed at x = 0, a clearance end at x = L (gap 1e-3 in front, 2e-3 behind), u0 with kinks off
// the node grid, v0 = 0: the end reaches both walls several times in 10 transits. (The event
// march is exact for piecewise-linear motions, which a piecewise-linear v0 that is not constant
// leaves when L/c is no multiple of dt: solver/README.md, 'Contact treatment'.)
bar::BarSetup clearance_bar(bool right) {
  bar::BarSetup s;
  const bar::End fixed{bar::EndType::fixed, 0};
  const bar::End clearance{bar::EndType::clearance, 1e-3, 2e-3};
  s.left = right ? fixed : clearance;
  s.right = right ? clearance : fixed;
  // Mirrored for the left end (x -> L - x, u -> -u keeps the walls' roles).
  const double sign = right ? 1 : -1;
  auto at = [&](double x) { return right ? x : 1 - x; };
  std::vector<double> ux{at(0.0), at(0.37), at(0.81), at(1.0)}, uy{0.0, 0.006, -0.004, 0.0};
  for (double& y : uy) y *= sign;
  if (!right) {
    std::reverse(ux.begin(), ux.end());
    std::reverse(uy.begin(), uy.end());
  }
  s.u0 = bar::PiecewiseLinear(ux, uy);
  s.v0 = bar::PiecewiseLinear::zero(1.0);
  return s;
}

TEST(Clearance, TdbemEventMatchesTheExactSolverOnBothWallsAndBothEnds) {
  for (bool right : {true, false}) {
    const bar::BarSetup s = clearance_bar(right);
    const double t_end = 10;
    const exact_bar::ExactBarSolution exact(s, t_end);
    ASSERT_TRUE(exact.ok()) << exact.message();
    const exact_bar::Side side = right ? exact_bar::Side::right : exact_bar::Side::left;
    int front = 0, back = 0;
    for (const auto& c : exact.contact_intervals(side)) (c.back_wall ? back : front) += 1;
    // Both walls are exercised (else this test could not fail on the back wall's logic).
    ASSERT_GE(front, 2);
    ASSERT_GE(back, 2);
    const double dt = 0.037;  // off the L/c grid: every closing is a fresh root
    TdbemMarch m(s, dt, ContactMethod::event);
    double worst_u = 0, worst_f = 0;
    const double energy0 = exact.energy(0);
    double worst_energy = 0;
    bool saw_tension = false;
    for (int k = 1; k * dt <= t_end; ++k) {
      const double t = k * dt;
      ASSERT_TRUE(m.advance_to(t));
      worst_u = std::max(worst_u, std::abs(m.end_displacement(right) - exact.u_end(side, t)));
      for (double x : {0.1, 0.45, 0.9})
        worst_u = std::max(worst_u, std::abs(m.displacement(x) - exact.u(x, t)));
      worst_energy = std::max(worst_energy, std::abs(m.energy() - energy0));
      // The force over the last sub-step (the force is piecewise constant in time, and every
      // front arriving at the end cuts a sub-step) against the exact force just before t.
      const double before = t - 1e-7 * dt;
      if (exact.in_contact(side, before) == m.in_contact(right)) {
        worst_f =
            std::max(worst_f, std::abs(m.end_force(right) - exact.contact_force(side, before)));
        saw_tension = saw_tension || m.end_force(right) < 0;
      }
    }
    // Piecewise-linear data: the event march is exact up to the round-off of ~100 contact
    // instants (relative 1e-13 of the 6e-3 amplitude, 1e-12 of the 1e-2 force and 5e-5 J).
    EXPECT_LT(worst_u, 6e-3 * 1e-12) << "right " << right;
    EXPECT_LT(worst_f, 1e-2 * 1e-10) << "right " << right;
    EXPECT_LT(worst_energy, energy0 * 1e-11) << "right " << right;
    EXPECT_TRUE(saw_tension) << "the back wall pulls: a negative compressive force";
    int back_events = 0;
    for (const ContactEvent& e : m.events()) back_events += e.back_wall && e.closing;
    EXPECT_EQ(back_events, back);
  }
}

TEST(Clearance, TdbemProjectionAndFemConvergeToTheExactSolver) {
  const bar::BarSetup s = clearance_bar(true);
  const double t_end = 6;
  const exact_bar::ExactBarSolution exact(s, t_end);
  ASSERT_TRUE(exact.ok());
  auto end_error = [&](const bar::History& h) {
    double worst = 0;
    for (std::size_t i = 0; i < h.t.size(); ++i)
      worst =
          std::max(worst, std::abs(h.u_contact[i] - exact.u_end(exact_bar::Side::right, h.t[i])));
    return worst;
  };
  double previous_tdbem = 1, previous_fem = 1;
  for (int elements : {100, 200, 400}) {
    bar::SimulationOptions o;
    o.t_end = t_end;
    o.dt = 1.0 / elements;
    o.elements = elements;
    const double e_tdbem = end_error(TdbemSolver(ContactMethod::projection).simulate(s, o));
    const double e_fem = end_error(fem_bar::FemBarSolver().simulate(s, o));
    // Both are first order at contact instants off the grid: halving dt must shrink the error
    // by a clear factor (1.5 leaves room for the irregular onset rounding of a first-order
    // scheme), and end below 10 % of the distance between the walls.
    EXPECT_LT(e_tdbem, previous_tdbem / 1.5) << elements;
    EXPECT_LT(e_fem, previous_fem / 1.5) << elements;
    if (elements == 400) {
      EXPECT_LT(std::max(e_tdbem, e_fem), 0.1 * 3e-3);  // of gap + gap_back
    }
    previous_tdbem = e_tdbem;
    previous_fem = e_fem;
  }
}

TEST(Clearance, AStateOnTheBackWallStartsClosedWithATensileForce) {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::clearance, 1e-3, 1e-3};
  // The symmetric clearance's mode 1 half a period on: on the back wall, slopes -s, +s.
  s.u0 = bar::PiecewiseLinear({0.0, 0.55, 1.0}, {0.0, -0.0055, -0.001});
  TdbemMarch m(s, 0.01, ContactMethod::event);
  EXPECT_TRUE(m.in_contact(true));
  EXPECT_NEAR(m.end_force(true), -0.01, 1e-15);  // EA u_x = 0.01, pulling
  const exact_bar::ExactBarSolution exact(s, 2.2);
  EXPECT_NEAR(exact.contact_force(exact_bar::Side::right, 0.1), -0.01, 1e-15);
  ASSERT_FALSE(exact.contact_intervals().empty());
  EXPECT_TRUE(exact.contact_intervals().front().back_wall);
}

TEST(Clearance, ABadClearanceIsRefusedByKey) {
  bar::BarSetup s;
  s.right = {bar::EndType::clearance, 0, 0};
  try {
    s.validate();
    FAIL() << "two coinciding walls accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), "gap_back");
  }
  s.right = {bar::EndType::clearance, 1e-3, 1e-3};
  s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, -2e-3});
  try {
    s.validate();
    FAIL() << "u0 through the back wall accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), "u0");
  }
}

}  // namespace
}  // namespace backbone::contact_bar
