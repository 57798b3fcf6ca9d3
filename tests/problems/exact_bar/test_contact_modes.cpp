// Contact: the exact first nonlinear mode (problems/contact_bar/orbits/README.md, 'Mode 1': onset
// (L + g0/|eps|)/c, release 2L/c, force EA|eps|, period T = (3L + g0/|eps|)/c), its mirror
// image with the contact at x = 0, energy conservation with contact, grazing and exact ties.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::exact_bar {
namespace {

struct ModeOne {
  double L, E, rho, A, eps, g0;
  double c() const { return std::sqrt(E / rho); }
  double onset() const { return (L + g0 / std::abs(eps)) / c(); }
  double release() const { return 2 * L / c(); }
  double period() const { return (3 * L + g0 / std::abs(eps)) / c(); }
  double force() const { return E * A * std::abs(eps); }
  double energy() const { return 0.5 * E * A * L * eps * eps; }
  bar::BarSetup setup() const {
    bar::BarSetup s;
    s.material = {L, E, rho, A};
    s.left = {bar::EndType::fixed, 0};
    s.right = {bar::EndType::contact, g0};
    s.u0 = bar::PiecewiseLinear({0.0, L}, {0.0, eps * L});
    return s;
  }
};

// Times: the events are sums and quotients of a few inputs, so a few ulps of the period;
// fields: a few ulps of |eps| L. 1e-13 relative leaves two orders of margin.
void check_mode_one(const ModeOne& m, int periods) {
  const double T = m.period();
  const ExactBarSolution sol = solve(m.setup(), periods * T);
  ASSERT_TRUE(sol.ok()) << sol.message();
  const auto contacts = sol.contact_intervals();
  ASSERT_EQ(contacts.size(), static_cast<std::size_t>(periods));
  for (int k = 0; k < periods; ++k) {
    EXPECT_NEAR(contacts[k].t_close, k * T + m.onset(), 1e-13 * periods * T) << k;
    EXPECT_NEAR(contacts[k].t_release, k * T + m.release(), 1e-13 * periods * T) << k;
    const double mid = k * T + 0.5 * (m.onset() + m.release());
    EXPECT_NEAR(sol.contact_force(mid), m.force(), 1e-13 * m.force());
    EXPECT_TRUE(sol.in_contact(Side::right, mid));
    EXPECT_EQ(sol.contact_force(k * T + 0.5 * m.onset()), 0.0);
  }
  const double scale = std::abs(m.eps) * m.L;
  for (int i = 0; i <= 20; ++i) {
    const double x = m.L * i / 20.0;
    EXPECT_NEAR(sol.u(x, T), m.eps * x, 1e-13 * scale);
    EXPECT_NEAR(sol.u(x, periods * T), m.eps * x, 1e-13 * scale);
    EXPECT_NEAR(sol.v(x, T), 0.0, 1e-13 * m.c() * std::abs(m.eps));
  }
  EXPECT_NEAR(sol.u_end(T), m.eps * m.L, 1e-13 * scale);
  for (double t = 0; t < periods * T; t += 0.0917 * T)
    EXPECT_NEAR(sol.energy(t), m.energy(), 1e-13 * m.energy()) << t;
}

TEST(ExactBarModeOne, PaperScene) {
  const ModeOne m{1, 1, 1, 1, -0.01, 1e-3};
  const ExactBarSolution sol = solve(m.setup(), 3.1);
  const auto contacts = sol.contact_intervals();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].t_close, 1.1, 1e-15);
  EXPECT_NEAR(contacts[0].t_release, 2.0, 1e-15);
  EXPECT_NEAR(sol.contact_force(1.5), 0.01, 1e-17);
  EXPECT_NEAR(sol.u_end(1.5), 1e-3, 1e-18);  // on the wall
  for (int i = 0; i <= 10; ++i) EXPECT_NEAR(sol.u(0.1 * i, 3.1), -0.001 * i, 1e-17);
  check_mode_one(m, 5);
}

TEST(ExactBarModeOne, OtherAmplitudesAndScaledMaterial) {
  for (double eps : {-0.0011, -0.003, -0.05, -1.0}) check_mode_one({1, 1, 1, 1, eps, 1e-3}, 3);
  check_mode_one({2.5, 4.0, 0.25, 3.0, -0.02, 0.003}, 4);    // c = 4
  check_mode_one({0.7, 210e9, 7800, 1e-4, -1e-4, 2e-5}, 3);  // steel-like, c ~ 5189
}

TEST(ExactBarModeOne, ContactAtLeftEndMirrorsRight) {
  // Mirror x -> L - x, u -> -u: the wall at u = -g0 on the left, fixed right end.
  const ModeOne m{1.3, 2.0, 0.5, 1.0, -0.01, 2e-3};
  bar::BarSetup s;
  s.material = {m.L, m.E, m.rho, m.A};
  s.left = {bar::EndType::contact, m.g0};
  s.right = {bar::EndType::fixed, 0};
  s.u0 = bar::PiecewiseLinear({0.0, m.L}, {-m.eps * m.L, 0.0});
  const double T = m.period();
  const ExactBarSolution sol = solve(s, 3 * T);
  const auto contacts = sol.contact_intervals();  // observed end: the left contact end
  ASSERT_EQ(contacts.size(), 3u);
  EXPECT_NEAR(contacts[0].t_close, m.onset(), 1e-13 * T);
  EXPECT_NEAR(contacts[0].t_release, m.release(), 1e-13 * T);
  const double mid = 0.5 * (m.onset() + m.release());
  EXPECT_NEAR(sol.contact_force(mid), m.force(), 1e-13 * m.force());  // compressive: > 0
  EXPECT_NEAR(sol.u_end(mid), -m.g0, 1e-16);
  EXPECT_NEAR(sol.u_end(Side::right, mid), 0.0, 0.0);
  EXPECT_TRUE(sol.contact_intervals(Side::right).empty());
  for (int i = 0; i <= 10; ++i) {
    const double x = m.L * i / 10;
    EXPECT_NEAR(sol.u(x, T), s.u0(x), 1e-13 * std::abs(m.eps) * m.L);
  }
}

TEST(ExactBarContact, EnergyConservedOver20PeriodsWithGenericData) {
  // Kinked u0, v0 and a gap the end reaches several times per period: many events, fronts
  // everywhere. Energy is conserved exactly by the dynamics (contact is an elastic reflection).
  bar::BarSetup s;
  s.material = {1.0, 1.0, 1.0, 1.0};
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 2e-3};
  s.u0 = bar::PiecewiseLinear({0.0, 0.3, 0.65, 1.0}, {0.0, -0.004, 0.002, -0.003});
  s.v0 = bar::PiecewiseLinear({0.0, 0.2, 0.8, 1.0}, {0.0, 0.01, -0.006, 0.002});
  const double t_end = 20 * 4.0;
  const ExactBarSolution sol = solve(s, t_end);
  ASSERT_TRUE(sol.ok());
  EXPECT_GT(sol.contact_intervals().size(), 10u);  // contact does happen, repeatedly
  const double e0 = sol.energy(0);
  double worst = 0;
  for (double t = 0; t <= t_end; t += 0.0731) worst = std::max(worst, std::abs(sol.energy(t) - e0));
  EXPECT_LT(worst / e0, 1e-13) << "relative energy drift " << worst / e0;
  // The displacement never penetrates the wall, and u(L, t) integrated through the bar from
  // u(0, t) (the field path) agrees with the end's own time integral (the event path).
  for (double t = 0; t <= t_end; t += 0.0173) {
    EXPECT_LE(sol.u_end(t), 2e-3 * (1 + 1e-14));
    EXPECT_NEAR(sol.u(1.0, t), sol.u_end(Side::right, t), 1e-13 * 4e-3);
  }
  // Cost is per segment, not per step: bounded growth per window.
  EXPECT_LT(sol.segment_count(), 200u * static_cast<std::size_t>(t_end));
}

TEST(ExactBarContact, ExactTieReachingTheWallAtAVelocityJumpIsNoContact) {
  // Fixed-free motion of u0 = eps x: the end reaches u = |eps| L exactly at t = 2, when its
  // velocity jumps from +|eps| c to -|eps| c. With the wall there, contact lasts zero time:
  // the motion must be the free 4L/c-periodic one, with no contact episode recorded.
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 0.01};
  s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, -0.01});
  const ExactBarSolution sol = solve(s, 40.0);
  EXPECT_TRUE(sol.contact_intervals().empty());
  for (int k = 1; k <= 10; ++k) {
    EXPECT_NEAR(sol.u_end(4.0 * k), -0.01, 1e-16);
    EXPECT_NEAR(sol.u_end(4.0 * k - 2), 0.01, 1e-16);
    EXPECT_NEAR(sol.u_end(4.0 * k - 1), 0.0, 1e-16);
  }
}

TEST(ExactBarContact, SmoothGrazingIsNoContact) {
  // Free-free bar thrown rigidly towards the wall against a body force: it stops exactly at
  // the wall (u = v0^2 / (2|b|) = 1 at t = 2) with zero velocity and comes back.
  bar::BarSetup s;
  s.material = {1.0, 1.0, 1.0, 1.0};
  s.left = {bar::EndType::free, 0};
  s.right = {bar::EndType::contact, 1.0};
  s.body_force = -0.5;
  s.u0 = bar::PiecewiseLinear::zero(1.0);
  s.v0 = bar::PiecewiseLinear({0.0, 1.0}, {1.0, 1.0});
  const ExactBarSolution sol = solve(s, 6.0);
  EXPECT_TRUE(sol.contact_intervals().empty());
  for (double t = 0; t <= 6.0; t += 0.25) {
    EXPECT_NEAR(sol.u_end(t), t - 0.25 * t * t, 1e-15) << t;
    EXPECT_NEAR(sol.u(0.3, t), t - 0.25 * t * t, 1e-15) << t;
    EXPECT_EQ(sol.contact_force(t), 0.0);
  }
}

TEST(ExactBarContact, BarInitiallyOnTheWallWithZeroGap) {
  // Gap 0 and a free-free bar moving rigidly into the wall: the end closes at t = 0, the
  // force is EA v / c until the wave reflected at the free end returns 2L/c later, then the
  // bar leaves rigidly with the opposite velocity (Newton's cradle).
  bar::BarSetup s;
  s.material = {2.0, 4.0, 1.0, 1.5};  // c = 2, L/c = 1
  s.left = {bar::EndType::free, 0};
  s.right = {bar::EndType::contact, 0.0};
  s.u0 = bar::PiecewiseLinear::zero(2.0);
  s.v0 = bar::PiecewiseLinear({0.0, 2.0}, {0.3, 0.3});
  const ExactBarSolution sol = solve(s, 5.0);
  const auto contacts = sol.contact_intervals();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].t_close, 0.0);
  EXPECT_NEAR(contacts[0].t_release, 2.0, 1e-15);
  EXPECT_NEAR(sol.contact_force(1.0), 4.0 * 1.5 * 0.3 / 2.0, 1e-15);  // EA v / c
  EXPECT_NEAR(sol.u_end(1.0), 0.0, 0.0);
  // After the impact the bar flies back rigidly with the opposite velocity.
  EXPECT_NEAR(sol.v(0.7, 4.5), -0.3, 1e-15);
  EXPECT_NEAR(sol.u_end(4.5), -0.3 * 2.5, 1e-15);
}

}  // namespace
}  // namespace backbone::exact_bar
