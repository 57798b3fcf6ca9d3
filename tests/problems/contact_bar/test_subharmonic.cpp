// The subharmonic continuum near omega2 / 2 (problems/contact_bar/README.md, section
// 'Subharmonic continuum'): its closed-form members checked by the exact characteristics
// solver (problems/exact_bar), and the TD-BEM started from their in-contact state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "problems/contact_bar/family.hpp"
#include "problems/contact_bar/tdbem.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {
namespace {

bar::BarSetup paper_setup(const bar::PiecewiseLinear& u0) {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 1e-3};
  s.u0 = u0;
  return s;
}

// Every member, at three energies and across the whole shape range, returns to its u0 and to
// v0 = 0 after T = 2 T2 under the exact solver: exact to round-off (the solver is exact for
// piecewise-linear data), so 1e-12 relative. Energy is EA L s^2 / 2 for every shape.
TEST(SubharmonicContinuum, ClosedFormMembersArePeriodic) {
  const bar::Material m;
  for (double energy : {4.6e-6, 1.25e-5, 1e-3})
    for (double shape : {0.0, 0.1, 0.25, 0.5, 0.8, 1.0}) {
      const SubharmonicMember member = subharmonic_member(m, 1e-3, energy, shape);
      const bar::BarSetup s = paper_setup(member.u0);
      EXPECT_DOUBLE_EQ(s.u0(1.0), 1e-3) << "starts on the wall";
      const exact_bar::ExactBarSolution sol(s, member.period);
      ASSERT_TRUE(sol.ok());
      double du = 0, dv = 0, u_max = 0;
      for (int i = 0; i <= 400; ++i) {
        const double x = i / 400.0;
        u_max = std::max(u_max, std::abs(s.u0(x)));
        du = std::max(du, std::abs(sol.u(x, member.period) - s.u0(x)));
        dv = std::max(dv, std::abs(sol.v(x, member.period)));
      }
      EXPECT_LT(du / u_max, 1e-12) << energy << " " << shape;
      EXPECT_LT(dv / u_max, 1e-12) << energy << " " << shape;
      EXPECT_NEAR(sol.energy(0.5 * member.period) / energy, 1, 1e-12);
    }
}

// The contact structure the issue describes: interior members have two contact phases per
// period of the closed-form durations (the first one split across t = 0 and t = T); at the
// limits one phase has shrunk to a grazing instant. Durations are exact event times (1e-12).
TEST(SubharmonicContinuum, ContactPhasesAndGrazingLimits) {
  const bar::Material m;
  const double energy = 1.25e-5;  // s = 5 g0: b = 0.3, each mode-2 phase lasts 1 - 3b = 0.1
  for (double shape : {0.0, 0.3, 0.5, 1.0}) {
    const SubharmonicMember member = subharmonic_member(m, 1e-3, energy, shape);
    EXPECT_NEAR(member.first_contact + member.second_contact, 0.2, 1e-12);
    const exact_bar::ExactBarSolution sol(paper_setup(member.u0), member.period);
    double first = 0, second = 0;
    for (const auto& c : sol.contact_intervals()) {
      const double release = std::min(c.t_release, member.period);
      if (c.t_close < 0.25 * member.period || c.t_close > 0.75 * member.period)
        first += release - c.t_close;
      else
        second += release - c.t_close;
    }
    EXPECT_NEAR(first, member.first_contact, 1e-12) << shape;
    EXPECT_NEAR(second, member.second_contact, 1e-12) << shape;
    if (shape == 0.0) {
      // Grazing at t = 0: on the wall, zero force, then leaving it (tensile strain at L).
      EXPECT_NEAR(sol.contact_force(1e-9), 0, 1e-15);
      EXPECT_GT(sol.strain(1.0, 0.0), 0);
    }
    if (shape == 1.0) {
      EXPECT_NEAR(sol.u_end(0.5 * member.period), 1e-3, 1e-15);  // grazes at T / 2
    }
  }
  // Mode 2 taken at the centre of its contact phase is the middle member: its two phases are
  // both 1 - 3b long.
  const SubharmonicMember middle = subharmonic_member(m, 1e-3, energy, 0.5);
  EXPECT_NEAR(middle.first_contact, 0.1, 1e-12);
  EXPECT_NEAR(middle.second_contact, 0.1, 1e-12);
}

// The TD-BEM from a state that starts on the wall with a compressive strain (issue 9, item 0):
// the contact force at t = 0 is the true -EA u0_x(L) (it was 0), and the event march follows the
// exact solver off the time grid (dt = 0.013 does not divide the contact instants): the event
// method is exact for piecewise-linear data, so round-off only (1e-12 relative to g0 and the
// force).
TEST(TdbemStartsInContact, MatchesExactSolver) {
  const bar::Material m;
  for (double shape : {0.3, 0.5, 1.0}) {
    const SubharmonicMember member = subharmonic_member(m, 1e-3, 1.25e-5, shape);
    const bar::BarSetup s = paper_setup(member.u0);
    const exact_bar::ExactBarSolution exact(s, member.period);
    TdbemMarch march(s, 0.013, ContactMethod::event);
    EXPECT_TRUE(march.in_contact(true));
    EXPECT_NEAR(march.end_force(true), exact.contact_force(0.0), 1e-15) << shape;
    EXPECT_NEAR(march.end_force(true), 5e-3, 1e-15);  // EA s
    double worst_u = 0;
    for (int k = 1; k <= 200; ++k) {
      const double t = member.period * k / 200.0;
      march.advance_to(t);
      worst_u = std::max(worst_u, std::abs(march.end_displacement(true) - exact.u_end(t)));
      for (double x : {0.2, 0.55, 0.9})
        worst_u = std::max(worst_u, std::abs(march.displacement(x) - exact.u(x, t)));
    }
    EXPECT_LT(worst_u / 1e-3, 1e-12) << shape;
  }
}

}  // namespace
}  // namespace backbone::contact_bar
