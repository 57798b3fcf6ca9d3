// Known-solution tests of the contact-bar shooting problem (contact_bar/orbits/periodic_bar):
// the exact mode-1 orbit u0 = eps x, T = (3L + g0/|eps|)/c (its
// problems/contact_bar/orbits/README.md, 'Mode 1') and the mode-2 tent (closed form derived in
// family.cpp) are roots of both formulations; the regular Jacobian is regular (nullity 1), the
// paper's T column vanishes; Newton returns to the family; short branches match the closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <thread>

#include "continuation/methods/pseudo_arclength.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/newton.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "tests/problems/contact_bar/paper_setup.hpp"

namespace {

using namespace backbone;
using contact_bar::ContactBarOrbitProblem;
using contact_bar::OrbitOptions;
using core::ShootingFormulation;
using core::Vector;

using test_support::kGap;
using test_support::paper_setup;

OrbitOptions grid(int elements, int steps, int free_knots = 0, int test_elements = 0) {
  OrbitOptions o;
  o.elements = elements;
  o.steps_per_period = steps;
  o.free_knots = free_knots;
  o.test_elements = test_elements;
  return o;
}

constexpr ShootingFormulation kBoth[] = {ShootingFormulation::displacement_periodicity,
                                         ShootingFormulation::half_period_velocity};

TEST(ContactBarOrbit, ExactModeOneIsARootOfBothFormulations) {
  const exact_bar::ExactBarSolver exact;
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  for (const bar::BarSolver* solver :
       {static_cast<const bar::BarSolver*>(&exact), static_cast<const bar::BarSolver*>(&event)}) {
    ContactBarOrbitProblem p(paper_setup(), *solver, grid(20, 40));
    for (double ratio : {1.2, 10.0, 141.0}) {
      const Vector x = p.contact_family_guess(1, ratio);  // u0 = eps x, |eps| = ratio g0 / L
      EXPECT_NEAR(x[p.period_index()], 3 + 1 / ratio, 1e-15);
      for (ShootingFormulation f : kBoth) {
        p.set_formulation(f);
        Vector r;
        ASSERT_EQ(p.residual(x, r), core::EvalStatus::ok);
        // Both solvers are exact for piecewise-linear data (event contact located inside the
        // step): only round-off of O(steps) operations on values of size |eps| L remains.
        // The residual is in units of the gap, and |eps| L = ratio g0.
        EXPECT_LE(r.lpNorm<Eigen::Infinity>(), 1e-12 * ratio)
            << solver->name() << " " << core::to_string(f) << " ratio " << ratio;
      }
    }
  }
}

TEST(ContactBarOrbit, ProjectionContactResidualIsFirstOrderInDt) {
  // The paper's Algorithm 1 puts contact onset on the time grid: the end lags by up to one
  // step at speed c|eps|, so the paper residual is bounded by about c |eps| dt, i.e.
  // ratio * dt in units of the gap (c = L = 1).
  const contact_bar::TdbemSolver projection(contact_bar::ContactMethod::projection);
  const double ratio = 7.3;
  for (int steps : {100, 1000}) {
    ContactBarOrbitProblem p(paper_setup(), projection, grid(20, steps));
    p.set_formulation(ShootingFormulation::displacement_periodicity);
    const Vector x = p.contact_family_guess(1, ratio);
    Vector r;
    ASSERT_EQ(p.residual(x, r), core::EvalStatus::ok);
    const double dt = p.time_step(x[p.period_index()]);
    EXPECT_LE(r.lpNorm<Eigen::Infinity>(), 2 * ratio * dt) << steps;
    EXPECT_GT(r.lpNorm<Eigen::Infinity>(), 1e-3 * ratio * dt) << steps;  // not exact
  }
}

TEST(ContactBarOrbit, RegularJacobianHasNullityOnePaperPeriodColumnVanishes) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  const int n = 20;
  ContactBarOrbitProblem p(paper_setup(), event, grid(n, 40));
  const Vector x = p.contact_family_guess(1, 3.0);
  core::FiniteDifferenceOptions central;
  central.scheme = core::FiniteDifferenceOptions::Scheme::central;

  p.set_formulation(ShootingFormulation::half_period_velocity);
  core::Matrix regular;
  ASSERT_EQ(core::finite_difference_jacobian(p, x, regular, central), core::EvalStatus::ok);
  const core::RankReport rep = core::rank_report(regular, core::RankOptions{});
  EXPECT_EQ(rep.nullity, 1) << rep.summary();
  // Not a threshold artefact: the smallest kept singular value is far above the cut-off (1e-8
  // relative), above 1e-5 of the largest.
  EXPECT_GT(rep.singular_values[n - 1], 1e-5 * rep.singular_values[0]) << rep.summary();
  EXPECT_GT(regular.col(n).norm(), 1e-2);  // the period matters at T/2

  p.set_formulation(ShootingFormulation::displacement_periodicity);
  core::Matrix paper;
  ASSERT_EQ(core::finite_difference_jacobian(p, x, paper, central), core::EvalStatus::ok);
  // df/dT = -v(., T) = 0 on the orbit (v0 = 0 and energy conservation); central differences
  // because the end turns at T (its velocity jumps from eps c to -eps c). FD noise bound:
  // round-off 1e-16 |u| / h with h ~ 6e-6 T.
  EXPECT_LE(paper.col(n).lpNorm<Eigen::Infinity>(), 1e-8) << paper.col(n).transpose();
}

TEST(ContactBarOrbit, NewtonReturnsToModeOneFromAPerturbedOrbit) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  const int n = 20;
  ContactBarOrbitProblem p(paper_setup(), event, grid(n, 40));
  Vector x = p.contact_family_guess(1, 3.0);
  for (int i = 0; i < n; ++i) x[i] *= 1 + 0.02 * std::sin(3.14159 * (i + 1.0) / n);  // smooth
  x[n] += 0.01;
  core::NewtonOptions options;
  options.residual_tolerance = 1e-11;  // in units of g0: 1e-14 m
  auto newton = core::make_corrector("eigen", options);
  const core::NewtonSummary s = newton->solve(p, x);
  ASSERT_TRUE(s.converged()) << s.message;
  EXPECT_LE(s.iterations, 8);
  // Back on the family: u0 = eps x and T = 3 + g0/|eps| at the eps Newton chose.
  const double eps = x[n - 1];
  // Tolerances: |F| <= 1e-14 m through a Jacobian of condition ~5e3 (sigma 19 / 3.5e-3).
  for (int i = 0; i < n; ++i) EXPECT_NEAR(x[i], eps * (i + 1.0) / n, 1e-10);
  EXPECT_NEAR(x[n], 3 + kGap / std::abs(eps), 1e-8);
  const exact_bar::ExactBarSolver exact;
  const contact_bar::ReturnError re = contact_bar::return_error(p, x, exact);
  EXPECT_LE(re.displacement, 1e-8);
  EXPECT_LE(re.velocity, 1e-4);  // a 1e-12 kink left in u0 sends fronts of v ~ c 1e-12 / dx
}

double worst_branch_error(const ContactBarOrbitProblem& p, int mode, int points, double ds,
                          int* count) {
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  continuation::ContinuationOptions o;
  o.ds = o.ds_max = ds;
  o.max_points = points;
  o.rank_check_every = 0;
  const Vector guess = p.contact_family_guess(mode, 1.05);
  const Vector direction = p.contact_family_guess(mode, 1.06) - guess;
  const continuation::Branch b = continuation::pseudo_arclength(p, guess, direction, *newton, o);
  *count = static_cast<int>(b.points.size());
  double worst = 0;
  for (const auto& point : b.points) {
    const double energy = point.observable("energy");
    const double exact =
        contact_bar::ContactFamily(p.setup_template().material, kGap, mode).frequency(energy);
    worst = std::max(worst, std::abs(point.observable("frequency") / exact - 1));
  }
  return worst;
}

TEST(ContactBarOrbit, ShortModeOneBranchMatchesTheClosedForm) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  ContactBarOrbitProblem p(paper_setup(), event, grid(10, 20));
  int count = 0;
  const double worst = worst_branch_error(p, 1, 30, 0.02, &count);
  EXPECT_EQ(count, 30);
  EXPECT_LE(worst, 1e-5);  // acceptance; the Newton tolerance 1e-10 on |F| leaves far less
}

TEST(ContactBarOrbit, ModeTwoTentIsExactWithAFreeKnotAndOnlyO_dx_OnAUniformGrid) {
  const exact_bar::ExactBarSolver exact;
  ContactBarOrbitProblem knot(paper_setup(), exact, grid(20, 40, 1));
  ContactBarOrbitProblem uniform(paper_setup(), exact, grid(20, 40, 0));
  for (ShootingFormulation f : kBoth) {
    knot.set_formulation(f);
    uniform.set_formulation(f);
    Vector r;
    const Vector xk = knot.contact_family_guess(2, 10.0);
    // Residuals in units of g0; the tent's values are about 21 g0: round-off only.
    ASSERT_EQ(knot.residual(xk, r), core::EvalStatus::ok);
    EXPECT_LE(r.lpNorm<Eigen::Infinity>(), 1e-12);
    const Vector xu = uniform.contact_family_guess(2, 10.0);  // crest between nodes
    ASSERT_EQ(uniform.residual(xu, r), core::EvalStatus::ok);
    EXPECT_GT(r.lpNorm<Eigen::Infinity>(), 1e-2);  // O(dx): a real miss, not round-off
  }
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  ContactBarOrbitProblem p(paper_setup(), event, grid(12, 20, 1));
  int count = 0;
  EXPECT_LE(worst_branch_error(p, 2, 20, 0.02, &count), 1e-5);
  EXPECT_EQ(count, 20);
}

// The square projected residual (N hat averages of v(T/2) for N unknowns) has spurious roots:
// with N = 20, a branch traced through end amplitudes 2.8-3 g0 leaves the contact family for
// orbits whose hat averages vanish while v(T/2) does not. Sampling the residual on 2N test
// functions makes the system overdetermined but consistent: true orbits zero every test
// function, spurious ones cannot zero 2N of them with N free values, and the same branch stays
// on the closed form.
TEST(ContactBarOrbit, OversampledResidualHasNoSpuriousRoots) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  int square_count = 0, over_count = 0;
  ContactBarOrbitProblem square(paper_setup(), event, grid(20, 40, 0, 0));
  ContactBarOrbitProblem over(paper_setup(), event, grid(20, 40, 0, 40));
  EXPECT_EQ(over.num_equations(), 40);
  // ds in scaled unknowns (RMS of u0 / g0 over the bar, T c / L): 0.45 is 2 in the Euclidean
  // norm of the 20 nodal values.
  const double square_error = worst_branch_error(square, 1, 70, 0.45, &square_count);
  const double over_error = worst_branch_error(over, 1, 70, 0.45, &over_count);
  EXPECT_GT(square_error, 1e-3);  // the failure this option exists for
  EXPECT_EQ(over_count, 70);
  EXPECT_LE(over_error, 1e-9);  // acceptance 1e-5; the Newton tolerance 1e-10 g0 leaves less
}

// The continuation norm of the u0 unknowns is the L2 norm of u0 over the bar (trapezoid rule,
// in units of g0 sqrt(L)): for u0 = eps x it is exactly |eps| L / g0 * sqrt(1/3 + 1/(6 N^2))
// (the trapezoid sum of x^2 on N intervals), within 1/(4 N^2) <= 7e-4 of |eps| L / (g0 sqrt(3)) at
// N = 20 and 640, where the Euclidean norm of the nodal values grows like sqrt(N).
TEST(ContactBarOrbit, StepNormIsTheL2NormOfU0AtEveryGrid) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  for (int n : {20, 640}) {
    ContactBarOrbitProblem p(paper_setup(), event, grid(n, 40));
    const continuation::ScaledProblem scaled(p);
    const double ratio = 7.0;  // |eps| L / g0
    const Vector z = scaled.to_scaled(p.contact_family_guess(1, ratio));
    const double expected = ratio * std::sqrt(1.0 / 3 + 1.0 / (6.0 * n * n));
    EXPECT_NEAR(z.head(n).norm(), expected, 1e-13 * expected) << n;  // round-off of N terms
    EXPECT_NEAR(z.head(n).norm(), ratio / std::sqrt(3.0), 7e-4 * ratio) << n;
    EXPECT_EQ(z[p.period_index()], 3 + 1 / ratio);  // period in units of L/c = 1
  }
}

// compute_residual is safe to call concurrently (each call marches its own TdbemMarch), and
// the columns are computed by the same operations on every thread: the default Jacobian with
// two threads equals the one-thread Jacobian bit for bit, on the contact bar and for a point
// in contact (the kinks and contact events of every column's march differ).
TEST(ContactBarOrbit, JacobianWithTwoThreadsIsBitIdentical) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  ContactBarOrbitProblem p(paper_setup(), event, grid(40, 40, 0, 80));
  const Vector x = p.contact_family_guess(1, 3.0);
  core::Matrix one, two;
  ASSERT_EQ(core::default_jacobian_threads(), 1);
  ASSERT_EQ(p.jacobian(x, one), core::EvalStatus::ok);
  core::set_default_jacobian_threads(2);
  const core::EvalStatus s = p.jacobian(x, two);
  core::set_default_jacobian_threads(1);
  ASSERT_EQ(s, core::EvalStatus::ok);
  EXPECT_TRUE(one == two);
  EXPECT_GT(one.norm(), 0);
  try {
    core::set_default_jacobian_threads(0);
    FAIL() << "accepted 0 threads";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), "threads");
  }
}

// clone() (core/problem.hpp): a copy that another thread evaluates while the original is
// evaluated gives the same bits (the same solver, the same x), and each counts only its own
// evaluations (the branch-point worker's rows and the loop's per-point counts stay exact).
TEST(ContactBarOrbit, CloneEvaluatesTheSameBitsOnAnotherThreadAndCountsItsOwn) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  ContactBarOrbitProblem p(paper_setup(), event, grid(40, 40, 0, 80));
  const Vector x = p.contact_family_guess(1, 3.0);
  const std::unique_ptr<core::Problem> copy = p.clone();
  ASSERT_NE(copy, nullptr);
  EXPECT_EQ(copy->counters().residuals, 0);
  Vector mine, theirs;
  core::Matrix J_mine, J_theirs;
  std::thread other([&] {
    for (int i = 0; i < 5; ++i) ASSERT_EQ(copy->residual(x, theirs), core::EvalStatus::ok);
    ASSERT_EQ(copy->jacobian(x, J_theirs), core::EvalStatus::ok);
  });
  for (int i = 0; i < 3; ++i) ASSERT_EQ(p.residual(x, mine), core::EvalStatus::ok);
  ASSERT_EQ(p.jacobian(x, J_mine), core::EvalStatus::ok);
  other.join();
  EXPECT_TRUE(mine == theirs);
  EXPECT_TRUE(J_mine == J_theirs);
  EXPECT_GT(mine.norm(), 0);
  // The Jacobian's own residuals come on top of the direct ones, the same number for both.
  EXPECT_EQ(copy->counters().residuals - 5, p.counters().residuals - 3);
  EXPECT_EQ(copy->counters().jacobians, 1);
  EXPECT_EQ(p.counters().jacobians, 1);
}

TEST(ContactBarOrbit, TestElementsBelowTheUnknownsAreRejected) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  try {
    ContactBarOrbitProblem p(paper_setup(), event, grid(20, 40, 1, 15));
    FAIL() << "accepted test_elements < unknowns";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), "test_elements");
    EXPECT_NE(std::string(e.what()).find(">= elements + free_knots = 21"), std::string::npos)
        << e.what();
  }
}

}  // namespace

// Step control over ten decades of energy (problems/contact_bar/orbits/README.md, section 'Jacobian
// pattern'): mode 1 from end amplitude 1.05 g0 (E = 5.5e-7 J) to E = 1e4 J (1.4e5 g0) with the
// trace's settings (20 intervals, 40 test elements, ds = ds_max = 0.45, Newton tolerance 3e-9, rank
// report with threshold 1e-5 at every point). In units of the gap a step moves u0 by about
// 0.45 g0 in L2, so the branch would need ~2e5 points: 200 points stay below 0.1 J. With
// amplitude_units the unit of u0 and of the residual is the orbit's amplitude and steps are
// relative: at most 50 points. Jacobians: one per Newton iteration plus the tangent (4-9),
// except above 1.2e5 g0, where mode 1's own smallest kept singular value falls below 1e-5
// relative (it shrinks like g0 / A) and the rank report probes a candidate: at most 30 a point
// on average (the probes vary with the points' exact position). The tangent's chord check
// (pseudo_arclength.cpp) keeps a forward-difference Jacobian across a kink of the contact map
// (near 8e3 J) from turning the tangent off the branch. Every point is an exact mode-1 orbit:
// within 1e-10 of the closed-form frequency (the Newton tolerance, relative to the amplitude,
// bounds the period error by ~1e-11).
TEST(ContactBarOrbit, HighEnergyModeOneTakesRelativeSteps) {
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  OrbitOptions options = grid(20, 40, 0, 40);
  const auto trace = [&](bool amplitude_units) {
    options.amplitude_units = amplitude_units;
    ContactBarOrbitProblem p(paper_setup(), event, options);
    core::NewtonOptions newton_options;
    newton_options.residual_tolerance = 3e-9;
    auto newton = core::make_corrector("eigen", newton_options);
    continuation::ContinuationOptions o;
    o.ds = o.ds_max = 0.45;
    o.max_points = 200;
    o.rank.relative_threshold = 1e-5;
    o.verification.residual_tolerance = 3e-9;
    o.bounds.push_back({"energy", 0.0, 1e4});
    const Vector guess = p.contact_family_guess(1, 1.05);
    const Vector direction = p.contact_family_guess(1, 1.05 * 1.01) - guess;  // as the trace
    return continuation::pseudo_arclength(p, guess, direction, *newton, o);
  };
  const continuation::Branch gap_units = trace(false);
  EXPECT_EQ(gap_units.reason, continuation::StopReason::max_points);
  EXPECT_LT(gap_units.points.back().observable("energy"), 0.1);
  const continuation::Branch b = trace(true);
  ASSERT_EQ(b.reason, continuation::StopReason::bound_reached) << b.message;
  EXPECT_LE(b.points.size(), 50u);
  EXPECT_NEAR(b.points.back().observable("energy"), 1e4, 1e-6);
  const contact_bar::ContactFamily family(paper_setup().material, kGap, 1);
  double jacobians = 0;
  int not_one = 0;
  for (const auto& point : b.points) {
    jacobians += static_cast<double>(point.jacobian_evaluations);
    // Far above the gap the period column dominates the Jacobian (sigma_max 2e6 at 6e4 g0) and
    // a probe can stall at the round-off just above its tolerance (verified 0, which the trace
    // flags unconfirmed): at most one such point, and only above 100 J.
    if (point.dimension != 1) {
      ++not_one;
      EXPECT_GT(point.observable("energy"), 100.0) << point.index;
    }
    const double energy = point.observable("energy");
    EXPECT_LE(std::abs(point.observable("frequency") / family.frequency(energy) - 1), 1e-10)
        << point.index << " at E = " << energy;
  }
  EXPECT_LE(not_one, 1);
  EXPECT_LE(jacobians / static_cast<double>(b.points.size()), 30.0);
}
