// Known-solution tests of contact_bar::ContactFamily against the exact characteristics solver:
// the closed-form period at an orbit's own energy is the time after which the exact oracle
// brings the orbit back to its initial state; the mode-2 node is where its u0 changes sign.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/errors.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace {

using namespace backbone;
using contact_bar::ContactFamily;

bar::BarSetup steel_bar(double gap) {
  bar::BarSetup s;
  s.material.length = 2.5;
  s.material.youngs_modulus = 2.1e11;
  s.material.density = 7850;
  s.material.area = 3e-4;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, gap};
  return s;
}

TEST(ContactFamily, ClosedFormPeriodIsTheExactOraclesReturnTime) {
  const double gap = 1e-4;
  const bar::BarSetup setup = steel_bar(gap);
  const exact_bar::ExactBarSolver exact;
  for (int mode : {1, 2}) {
    contact_bar::OrbitOptions o;
    o.elements = 20;
    o.free_knots = mode == 2 ? 1 : 0;
    contact_bar::ContactBarOrbitProblem orbit(setup, exact, o);
    const ContactFamily family(setup.material, gap, mode);
    for (double ratio : {1.3, 7.0, 60.0}) {
      core::Vector x = orbit.contact_family_guess(mode, ratio);
      const double energy = orbit.energy(x);
      // The family's period from the energy alone, put into the orbit: the exact oracle must
      // return it to u0 to round-off (piecewise-linear data, exact solver: 1e-11 relative
      // leaves room for the ~1e3 characteristic crossings of one period).
      x[orbit.period_index()] = family.period(energy);
      const contact_bar::ReturnError e = contact_bar::return_error(orbit, x, exact, 200);
      EXPECT_LT(e.worst(), 1e-11) << "mode " << mode << " ratio " << ratio;
      EXPECT_NEAR(family.frequency(energy) * family.period(energy), 2 * std::numbers::pi, 1e-14);
      EXPECT_GT(energy, family.grazing_energy());
      if (mode == 2) {
        // The tent's sign change, read off the sampled u0 (its knot sits at the crest), is
        // the closed-form node 2bL to round-off.
        const double node = contact_bar::node_of(orbit.initial_displacement(x));
        EXPECT_NEAR(node, family.node(energy), 1e-12 * setup.material.length);
      } else {
        EXPECT_TRUE(std::isnan(family.node(energy)));
      }
    }
  }
}

TEST(ContactFamily, GrazingAndLimits) {
  const double gap = 1e-3;
  bar::Material paper;  // E = rho = L = A = 1
  const ContactFamily mode1(paper, gap, 1), mode2(paper, gap, 2);
  // At grazing the period is the linear one, 4L/c (mode 1) and 4L/(3c) (mode 2).
  EXPECT_NEAR(mode1.period(mode1.grazing_energy() * (1 + 1e-14)), 4.0, 1e-12);
  EXPECT_NEAR(mode2.period(mode2.grazing_energy() * (1 + 1e-14)), 4.0 / 3.0, 1e-12);
  EXPECT_NEAR(mode1.frequency(mode1.grazing_energy() * (1 + 1e-14)), mode1.linear_frequency(),
              1e-12);
  EXPECT_NEAR(mode2.frequency(mode2.grazing_energy() * (1 + 1e-14)), mode2.linear_frequency(),
              1e-12);
  // Far above grazing the frequencies approach 2 pi c/(3L) and 8 pi c/(5L): exactly
  // omega_inf / omega = 1 + (g0/s)/(3L) (mode 1) and 1 + (g0/s)/(5L) (mode 2).
  for (double e : {1e2, 1e6}) {
    EXPECT_NEAR(mode1.asymptotic_frequency() / mode1.frequency(e), 1 + gap / mode1.slope(e) / 3,
                1e-14);
    EXPECT_NEAR(mode2.asymptotic_frequency() / mode2.frequency(e), 1 + gap / mode2.slope(e) / 5,
                1e-14);
  }
  EXPECT_TRUE(std::isnan(mode1.frequency(0.5 * mode1.grazing_energy())));
  EXPECT_THROW(ContactFamily(paper, gap, 0), core::InputError);
  EXPECT_THROW(ContactFamily(paper, 0.0, 1), core::InputError);
}

}  // namespace

namespace {

// Mode J (README.md, section 'Mode J'): the closed-form u0 at energy E, simulated over the
// closed-form period by the exact oracle, comes back to itself. Its slopes are +-s, its J - 1
// kinks where the derivation puts them; J = 1 and 2 are u0 = -s x and the tent of 'Mode 2'.
TEST(ContactFamily, ModeJReturnsToItsClosedFormAfterItsPeriod) {
  const exact_bar::ExactBarSolver exact;
  for (double gap : {1e-3, 5e-3}) {
    bar::BarSetup setup;
    setup.left = {bar::EndType::fixed, 0};
    setup.right = {bar::EndType::contact, gap};
    if (gap == 5e-3) {  // another bar: L = 2, c = 2
      setup.material.length = 2;
      setup.material.youngs_modulus = 4;
    }
    const double length = setup.material.length;
    for (int mode : {1, 2, 3, 4, 5, 8}) {
      const ContactFamily family(setup.material, gap, mode);
      for (double factor : {1.21, 100.0}) {
        const double energy = factor * family.grazing_energy();
        const double s = family.slope(energy);
        const bar::PiecewiseLinear u0 = family.u0(energy);
        ASSERT_EQ(u0.knots().size(), static_cast<std::size_t>(mode + 1)) << mode;
        for (std::size_t k = 1; k < u0.knots().size(); ++k) {
          const double slope =
              (u0.values()[k] - u0.values()[k - 1]) / (u0.knots()[k] - u0.knots()[k - 1]);
          // Each segment's slope from two knot values a few L apart: round-off of s.
          EXPECT_NEAR(std::abs(slope) / s, 1, 1e-11) << "mode " << mode << " segment " << k;
        }
        EXPECT_NEAR(u0(length), -(s * length - (mode - 1) * gap) / mode, 1e-14 * length);
        if (mode == 1) {
          EXPECT_NEAR(u0(0.5 * length), -s * 0.5 * length, 1e-15);
        }
        if (mode == 2) {
          EXPECT_NEAR(u0.knots()[1], 0.25 * (1 + gap / (s * length)) * length, 1e-15);
        }
        setup.u0 = u0;
        bar::SnapshotRequest r;
        r.elements = 200;
        const bar::FieldSnapshot snap = exact.snapshot(setup, family.period(energy), r);
        ASSERT_TRUE(snap.ok) << snap.message;
        double worst = 0, scale = 0;
        for (std::size_t i = 0; i < snap.x.size(); ++i) {
          worst = std::max(worst, std::abs(snap.u[i] - u0(snap.x[i])));
          scale = std::max(scale, std::abs(u0(snap.x[i])));
        }
        // Piecewise-linear data, exact solver: round-off of some 1e2 characteristic crossings.
        EXPECT_LT(worst / scale, 1e-11) << "mode " << mode << " E/E_graze " << factor;
      }
    }
  }
}

// At grazing the mode-J orbit is the linear mode J (period 4L/((2J - 1) c)); far above it the
// period tends to (2J + 1) L / (J^2 c).
TEST(ContactFamily, ModeJGrazesAtTheLinearPeriodAndHardensToItsLimit) {
  const bar::Material paper;  // c = L = 1
  for (int mode : {3, 4, 5, 8}) {
    const ContactFamily family(paper, 1e-3, mode);
    EXPECT_NEAR(family.period(family.grazing_energy() * (1 + 1e-14)), 4.0 / (2 * mode - 1), 1e-12);
    EXPECT_NEAR(family.frequency(family.grazing_energy() * (1 + 1e-14)), family.linear_frequency(),
                1e-10);
    EXPECT_NEAR(family.asymptotic_frequency() / family.frequency(1e8), 1, 1e-6);
    EXPECT_TRUE(std::isnan(family.period(0.99 * family.grazing_energy())));
  }
}

}  // namespace

// The clearance modes (README.md, 'Modes in a clearance') against the exact characteristics
// solver, which knows nothing of the derivation: after the closed-form period u0 is back and
// v = 0; each wall holds for its closed-form duration once per period; the energy is
// EA L s^2 / 2. Symmetric (gap_back = gap) and asymmetric (3 gap) clearances, below and above
// the back wall's grazing energy, on the paper's bar and on one with L = 2, c = 2.
TEST(ClearanceMode, ReturnsAfterItsPeriodWithOnePhaseOnEachWall) {
  for (double gap : {1e-3, 5e-3}) {
    bar::BarSetup setup;
    setup.left = {bar::EndType::fixed, 0};
    if (gap == 5e-3) {
      setup.material.length = 2;
      setup.material.youngs_modulus = 4;
    }
    const double length = setup.material.length, c = setup.material.wave_speed();
    for (double back_factor : {1.0, 3.0}) {
      setup.right = {bar::EndType::clearance, gap, back_factor * gap};
      for (int mode : {1, 2, 3, 5}) {
        const contact_bar::ClearanceMode family(setup.material, gap, back_factor * gap, mode);
        // Symmetric: both walls from grazing on. Asymmetric: one-sided up to the back grazing.
        EXPECT_NEAR(family.back_grazing_energy() / family.grazing_energy(),
                    back_factor == 1 ? 1.0 : std::pow((4.0 * mode - 1) / (2 * mode - 1), 2), 1e-12);
        for (double factor : {1.21, 1.9, 100.0}) {
          const double energy = factor * family.grazing_energy();
          const bool two_walls = energy > family.back_grazing_energy();
          const bar::PiecewiseLinear u0 = family.u0(energy);
          ASSERT_EQ(u0.knots().size(), static_cast<std::size_t>(mode + 2)) << mode;
          const double s = family.slope(energy);
          for (std::size_t k = 1; k < u0.knots().size(); ++k) {
            const double slope =
                (u0.values()[k] - u0.values()[k - 1]) / (u0.knots()[k] - u0.knots()[k - 1]);
            // Each slope from two knot values a few L apart: round-off of s (the first
            // segment ends on u0(0) = 0 set exactly, so it checks that the kinks add up).
            EXPECT_NEAR(std::abs(slope) / s, 1, 1e-10) << "mode " << mode << " segment " << k;
          }
          EXPECT_EQ(u0(length), gap);
          setup.u0 = u0;
          const double period = family.period(energy);
          const exact_bar::ExactBarSolution sol(setup, period);
          ASSERT_TRUE(sol.ok()) << sol.message();
          double worst_u = 0, worst_v = 0, scale = 0;
          for (int i = 0; i <= 200; ++i) {
            const double x = length * i / 200;
            worst_u = std::max(worst_u, std::abs(sol.u(x, period) - u0(x)));
            worst_v = std::max(worst_v, std::abs(sol.v(x, period)) * length / c);
            scale = std::max(scale, std::abs(u0(x)));
          }
          // Piecewise-linear data, exact solver: round-off of some 1e2 characteristic crossings.
          EXPECT_LT(worst_u / scale, 1e-11) << mode << " " << back_factor << " " << factor;
          EXPECT_LT(worst_v / scale, 1e-11) << mode << " " << back_factor << " " << factor;
          EXPECT_NEAR(sol.energy(0) / (0.5 * setup.material.axial_stiffness() * length * s * s), 1,
                      1e-12);
          // One phase per wall per period: the one through t = 0 = T (front) appears as
          // [0, a) and [T - a', T]; the back one lies inside.
          double front = 0, back = 0;
          int back_phases = 0;
          for (const auto& ci : sol.contact_intervals(exact_bar::Side::right)) {
            const double d = std::min(ci.t_release, period) - ci.t_close;
            if (ci.back_wall) {
              back += d;
              ++back_phases;
            } else {
              front += d;
            }
          }
          EXPECT_EQ(back_phases, two_walls ? 1 : 0) << mode << " " << factor;
          // Durations: instants of exact roots, a few ulps of the period.
          EXPECT_NEAR(front, family.front_contact(energy), 1e-12 * period);
          EXPECT_NEAR(back, family.back_contact(energy), 1e-12 * period);
          if (!two_walls) {  // the one-sided mode J, whatever the clearance behind
            EXPECT_NEAR(period, ContactFamily(setup.material, gap, mode).period(energy),
                        1e-14 * period);
          }
        }
      }
    }
  }
}

// At the linear grazing the symmetric clearance's mode J is the linear mode J (period
// 4L / ((2J - 1) c)); far above it every mode tends to the fixed-fixed bar, T -> 2L / (J c).
TEST(ClearanceMode, GrazesAtTheLinearPeriodAndTendsToTheFixedFixedBar) {
  const bar::Material paper;  // c = L = 1
  for (int mode : {1, 2, 3}) {
    const contact_bar::ClearanceMode m(paper, 1e-3, 1e-3, mode);
    EXPECT_NEAR(m.period(m.grazing_energy() * (1 + 1e-14)), 4.0 / (2 * mode - 1), 1e-12);
    EXPECT_NEAR(m.period(1e24 * m.grazing_energy()), 2.0 / mode, 1e-10);  // gamma ~ 1e-12
    // The asymmetric one is continuous where the back wall joins.
    const contact_bar::ClearanceMode a(paper, 1e-3, 3e-3, mode);
    const double e = a.back_grazing_energy();
    EXPECT_NEAR(a.period(e * (1 + 1e-13)), a.period(e), 1e-12);
    EXPECT_NEAR(a.back_contact(e * (1 + 1e-13)), 0, 1e-12);
  }
  EXPECT_THROW(contact_bar::ClearanceMode(paper, 3e-3, 1e-3, 1), core::InputError);
}
