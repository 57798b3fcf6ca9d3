// The contact bar's Jacobian pattern (ContactBarOrbitProblem::jacobian_pattern,
// problems/contact_bar/orbits/README.md, section 'Jacobian pattern') against the column-by-column
// finite-difference Jacobian, which knows nothing of characteristics: modes 1 and 2 (free
// knot), both formulations, the TD-BEM and the exact solver, N = 20 and 80, energies from just
// above grazing (|u0(L)| = 1.02 g0) to 141 g0 (2e4 times the grazing energy), at the
// closed-form orbits of the family (roots of both residuals), and at rough points off it.
#include <gtest/gtest.h>

#include <cmath>

#include "core/jacobians/compressed_jacobian.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/solver/bar_solvers.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "tests/problems/contact_bar/paper_setup.hpp"

namespace {

using namespace backbone;
using contact_bar::ContactBarOrbitProblem;
using contact_bar::OrbitOptions;
using core::ShootingFormulation;
using core::Vector;

using test_support::paper_setup;

OrbitOptions trace_grid(int n, int mode, int steps = 40) {
  OrbitOptions o;  // the trace's grid: 40 steps per period (its default), 2N test elements
  o.elements = n;
  o.steps_per_period = steps;
  o.test_elements = 2 * n;
  o.free_knots = mode == 2 ? 1 : 0;
  return o;
}

TEST(ContactBarJacobianPattern, CompressedEqualsColumnByColumnOnModesOneAndTwo) {
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  const exact_bar::ExactBarSolver exact;
  for (const bar::BarSolver* solver :
       {static_cast<const bar::BarSolver*>(&tdbem), static_cast<const bar::BarSolver*>(&exact)})
    for (int mode : {1, 2})
      for (ShootingFormulation f : {ShootingFormulation::half_period_velocity,
                                    ShootingFormulation::displacement_periodicity})
        for (int n : {20, 80})
          for (int steps : {40, 2 * n})
            for (double ratio : {1.02, 1.5, 10.0, 141.0}) {
              SCOPED_TRACE(::testing::Message()
                           << solver->name() << " mode " << mode << " " << core::scene_name(f)
                           << " N " << n << " steps " << steps << " |u0(L)|/g0 " << ratio);
              ContactBarOrbitProblem p(paper_setup(), *solver, trace_grid(n, mode, steps));
              p.set_formulation(f);
              const Vector x = p.contact_family_guess(mode, ratio);
              const auto pattern = p.jacobian_pattern(x);
              ASSERT_TRUE(pattern);
              core::Matrix dense, compressed;
              ASSERT_EQ(core::finite_difference_jacobian(p, x, dense), core::EvalStatus::ok);
              core::CompressedJacobianReport report;
              ASSERT_EQ(core::compressed_finite_difference_jacobian(p, x, *pattern, compressed, {},
                                                                    &report),
                        core::EvalStatus::ok);
              EXPECT_FALSE(report.fell_back) << "check " << report.check_error;
              // At N = 20 the images of a row cover most of the bar; at N = 80 with 2N steps
              // they do not for the regular residual (with 40 steps a step spans 6 elements and
              // the window of c dt around each image covers much of the bar; the paper's
              // release columns are dense).
              if (n == 80 && steps == 2 * n && f == ShootingFormulation::half_period_velocity) {
                EXPECT_LT(report.colours, p.num_unknowns() / 2);
              }
              // In the column-scaled Jacobian J diag(typical scale) (steps h_j = sqrt(eps) s_j),
              // a right pattern changes an entry only by F's round-off over h: the other columns
              // of its colour are absent from the row but change the rounding of the simulation,
              // ~ sqrt(eps) |J|, far below the bound. A dropped entry of the size of
              // the finite-difference error itself (1e-6, second-order terms) would fail.
              const Vector s = p.typical_scale();
              const double size = (dense * s.asDiagonal()).cwiseAbs().maxCoeff();
              EXPECT_LT(((compressed - dense) * s.asDiagonal()).cwiseAbs().maxCoeff(), 1e-6 * size);
            }
}

TEST(ContactBarJacobianPattern, HoldsOffTheFamilyWhereTheTdbemSmearsOverAStep) {
  // A rough u0 (node values jagged by up to 1e-2 .. 1e-1 g0, far from any orbit): the TD-BEM
  // interpolates its end histories over a step, so a row reads u0 over c dt around each image
  // (at 40 steps per period and N = 160, 13 elements); on the linear pieces of the family
  // orbits that interpolation is exact and hides it. The bare supports then drop entries of
  // the size of the largest one (at roughness 1e-1); the margin of c dt holds.
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  for (int n : {80, 160})
    for (double roughness : {1e-2, 1e-1}) {
      SCOPED_TRACE(::testing::Message() << "N " << n << " roughness " << roughness);
      ContactBarOrbitProblem p(paper_setup(), tdbem, trace_grid(n, 1, 40));
      Vector x = p.contact_family_guess(1, 1.25);
      for (int j = 0; j < n; ++j) x[j] += roughness * 1e-3 * std::sin(7.1 * j + 0.3 * j * j);
      const auto pattern = p.jacobian_pattern(x);
      ASSERT_TRUE(pattern);
      core::Matrix dense, compressed;
      ASSERT_EQ(core::finite_difference_jacobian(p, x, dense), core::EvalStatus::ok);
      core::CompressedJacobianReport report;
      ASSERT_EQ(
          core::compressed_finite_difference_jacobian(p, x, *pattern, compressed, {}, &report),
          core::EvalStatus::ok);
      EXPECT_FALSE(report.fell_back) << "check " << report.check_error;
      const Vector s = p.typical_scale();
      const double size = (dense * s.asDiagonal()).cwiseAbs().maxCoeff();
      // Tolerance as above: round-off of F over h, ~ sqrt(eps) |J|.
      EXPECT_LT(((compressed - dense) * s.asDiagonal()).cwiseAbs().maxCoeff(), 1e-6 * size);
    }
}

TEST(ContactBarJacobianPattern, OnlyTheCharacteristicSolversWithoutPathRowsHaveOne) {
  const auto fem = contact_bar::make_bar_solver("fem", contact_bar::ContactMethod::event);
  ContactBarOrbitProblem on_fem(paper_setup(), *fem, trace_grid(20, 1));
  EXPECT_FALSE(on_fem.jacobian_pattern(on_fem.contact_family_guess(1, 2.0)));
  const contact_bar::TdbemSolver tdbem;
  OrbitOptions with_energy_row = trace_grid(20, 1);
  with_energy_row.fixed_energy = 1e-4;  // a dense row
  ContactBarOrbitProblem bordered(paper_setup(), tdbem, with_energy_row);
  const Vector x = bordered.contact_family_guess(1, 2.0);
  EXPECT_FALSE(bordered.jacobian_pattern(x));
  bordered.set_path_rows(false);
  EXPECT_TRUE(bordered.jacobian_pattern(x));
}

TEST(ContactBarJacobianPattern, TheDefaultJacobianUsesItWithoutFallingBack) {
  const contact_bar::TdbemSolver tdbem;
  ContactBarOrbitProblem p(paper_setup(), tdbem, trace_grid(80, 1, 160));
  const Vector x = p.contact_family_guess(1, 3.0);
  core::Matrix J;
  ASSERT_EQ(p.jacobian(x, J), core::EvalStatus::ok);
  EXPECT_EQ(p.counters().compressed_jacobians, 1);
  EXPECT_EQ(p.counters().jacobian_fallbacks, 0);
  // 81 columns, 160 steps per period: at most half as many residuals (F(x), colours, check).
  EXPECT_LT(p.counters().residuals, 41);
}

}  // namespace
