// The bouncing bar: the hand-derived closed form (bouncing_bar.cpp) against the event-driven
// solver over 10 periods, and the published landmarks (landing at t = 1 with speed 10,
// force 300 -> 500, impacts of 2L/c, period 16L/c = 16/3).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "problems/exact_bar/bouncing_bar.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::exact_bar {
namespace {

constexpr double period = 16.0 / 3.0;

TEST(BouncingBar, ClosedFormLandmarks) {
  EXPECT_DOUBLE_EQ(bouncing_bar_period(), period);
  EXPECT_NEAR(bouncing_bar_contact_displacement(0.0), 0.0, 0.0);
  EXPECT_NEAR(bouncing_bar_contact_displacement(1.0), 5.0, 1e-15);
  EXPECT_NEAR(bouncing_bar_contact_displacement(1.0 - 1e-6), 5.0 - 10e-6, 1e-9);  // speed 10
  EXPECT_NEAR(bouncing_bar_contact_force(1.0), 300.0, 1e-12);
  EXPECT_NEAR(bouncing_bar_contact_force(5.0 / 3.0 - 1e-12), 500.0, 1e-8);
  EXPECT_EQ(bouncing_bar_contact_force(5.0 / 3.0 + 1e-12), 0.0);
  EXPECT_NEAR(bouncing_bar_contact_force(11.0 / 3.0 + 1e-12), 500.0, 1e-8);
  EXPECT_NEAR(bouncing_bar_contact_force(13.0 / 3.0 - 1e-12), 300.0, 1e-8);
  // Continuous displacement at every phase boundary.
  for (double tb : {1.0, 5.0 / 3.0, 7.0 / 3.0, 3.0, 11.0 / 3.0, 13.0 / 3.0, period}) {
    EXPECT_NEAR(bouncing_bar_contact_displacement(tb - 1e-9),
                bouncing_bar_contact_displacement(tb + 1e-9), 1e-7)
        << tb;
  }
}

TEST(BouncingBar, SolverLandsAtOneAndHasTwoImpactsPerPeriod) {
  const ExactBarSolution sol = solve(bouncing_bar_setup(), 10 * period);
  ASSERT_TRUE(sol.ok()) << sol.message();
  const auto contacts = sol.contact_intervals();
  ASSERT_EQ(contacts.size(), 20u);
  EXPECT_NEAR(contacts[0].t_close, 1.0, 1e-14);
  EXPECT_NEAR(sol.v(10.0, 1.0 - 1e-9), 10.0, 1e-7);  // landing speed
  for (int k = 0; k < 10; ++k) {
    const double t0 = k * period;
    // Event times are sums of ~50 windows of L/c: round-off of a few ulps of 50.
    EXPECT_NEAR(contacts[2 * k].t_close, t0 + 1.0, 1e-12) << k;
    EXPECT_NEAR(contacts[2 * k].t_release, t0 + 5.0 / 3.0, 1e-12) << k;  // lasts 2L/c
    EXPECT_NEAR(contacts[2 * k + 1].t_close, t0 + 11.0 / 3.0, 1e-12) << k;
    EXPECT_NEAR(contacts[2 * k + 1].t_release, t0 + 13.0 / 3.0, 1e-12) << k;
  }
}

TEST(BouncingBar, ClosedFormMatchesSolverOver10Periods) {
  const ExactBarSolution sol = solve(bouncing_bar_setup(), 10 * period);
  // Event instants (mod period) where the force jumps: a sample within round-off of one of
  // them may legitimately fall on either side, so samples keep 1e-9 away.
  const std::vector<double> jumps{1.0, 5.0 / 3.0, 11.0 / 3.0, 13.0 / 3.0};
  double err_u = 0, err_f = 0;
  int samples = 0;
  for (double t = 0; t <= 10 * period; t += 0.00731) {
    const double phase = std::fmod(t, period);
    bool near_jump = false;
    for (double j : jumps) near_jump |= std::abs(phase - j) < 1e-9;
    if (near_jump) continue;
    ++samples;
    err_u = std::max(err_u, std::abs(sol.u_end(t) - bouncing_bar_contact_displacement(t)));
    err_f = std::max(err_f, std::abs(sol.contact_force(t) - bouncing_bar_contact_force(t)));
  }
  EXPECT_GT(samples, 7000);
  // Displacements ~5 and forces ~500 at t ~ 50: the sample times themselves carry ~1e-14 of
  // round-off, times velocities ~10 and force rates ~300: a few 1e-13 at most.
  EXPECT_LT(err_u, 1e-12) << "max |u_end - closed form| = " << err_u;
  EXPECT_LT(err_f, 1e-12) << "max |force - closed form| = " << err_f;
}

TEST(BouncingBar, EnergyWithGravityIsConserved) {
  const ExactBarSolution sol = solve(bouncing_bar_setup(), 10 * period);
  // E(0) = 0 (at rest, undeformed, u = 0); the scale is the kinetic energy at landing,
  // 1/2 rho A L v^2 = 500; only round-off of that scale is allowed.
  for (double t = 0; t <= 10 * period; t += 0.0377)
    EXPECT_NEAR(sol.energy(t), 0.0, 1e-13 * 500) << t;
  // The bar vibrates between the impacts (the free end does not follow the contact end) and
  // is back at rest, undeformed, each period.
  EXPECT_GT(std::abs(sol.strain(5.0, 2.0)), 0.01);
  EXPECT_NEAR(sol.contact_force(1.0 + 1e-12), 300.0, 1e-8);  // force rises 300 -> 500
  EXPECT_NEAR(sol.contact_force(5.0 / 3.0 - 1e-12), 500.0, 1e-8);
  for (double x : {0.0, 3.3, 10.0}) {
    EXPECT_NEAR(sol.v(x, 5 * period), 0.0, 1e-11);
    EXPECT_NEAR(sol.u(x, 5 * period), 0.0, 1e-11);
  }
}

}  // namespace
}  // namespace backbone::exact_bar
