// Newton correctors: options validation, convergence on small square systems (both backends),
// quadratic convergence, backend parity, minimum-norm steps on an under-determined system,
// numerical failure as a status.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>

#include "core/errors.hpp"
#include "core/solvers/eigen_newton.hpp"
#include "core/solvers/kinsol_newton.hpp"
#include "core/solvers/newton.hpp"
#include "tests/core/test_problems.hpp"

namespace backbone::core {
namespace {

using testing::CircleLine;
using testing::NanBeyondHalf;
using testing::Rosenbrock;
using testing::Sphere;

// Expects `body` to throw InputError whose key is `key`.
template <class F>
void expect_input_error(F body, const std::string& key) {
  try {
    body();
    ADD_FAILURE() << "no InputError for " << key;
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
  }
}

TEST(NewtonOptions, DefaultsAreValid) {
  EXPECT_NO_THROW(NewtonOptions{}.validate());
}

TEST(NewtonOptions, ValidationNamesTheField) {
  NewtonOptions o;
  o.max_iterations = 0;
  expect_input_error([&] { o.validate(); }, "newton.max_iterations");
  o = {};
  o.residual_tolerance = std::nan("");
  expect_input_error([&] { o.validate(); }, "newton.residual_tolerance");
  o = {};
  o.step_tolerance = -1;
  expect_input_error([&] { o.validate(); }, "newton.step_tolerance");
  o = {};
  o.rank_cutoff = 1.5;
  expect_input_error([&] { o.validate(); }, "newton.rank_cutoff");
  // Constructors validate too.
  o = {};
  o.max_iterations = -3;
  expect_input_error([&] { EigenNewton e(o); }, "newton.max_iterations");
  expect_input_error([&] { KinsolNewton k(o); }, "newton.max_iterations");
}

TEST(NewtonOptions, MakeCorrectorByName) {
  EXPECT_EQ(make_corrector("eigen", {})->name(), "eigen");
  EXPECT_EQ(make_corrector("kinsol", {})->name(), "kinsol");
  expect_input_error([] { make_corrector("lapack", {}); }, "newton");
}

TEST(NewtonStatus, Names) {
  EXPECT_STREQ(to_string(NewtonStatus::converged), "converged");
  EXPECT_STREQ(to_string(NewtonStatus::evaluation_failed), "evaluation_failed");
}

// Quadratic convergence: once e_k is small (< 1e-2) and e_{k+1} is above round-off (> 1e-13),
// log e_{k+1} / log e_k must be close to 2 (1.7 leaves room for the constant in
// e_{k+1} ~ C e_k^2; linear convergence gives ~1). At least one such pair must exist, so the
// test fails if the history is too short to tell.
void expect_quadratic(const std::vector<double>& h) {
  int pairs = 0;
  for (std::size_t k = 0; k + 1 < h.size(); ++k) {
    if (h[k] < 1e-2 && h[k + 1] > 1e-13) {
      ++pairs;
      EXPECT_GT(std::log(h[k + 1]) / std::log(h[k]), 1.7) << "step " << k;
    }
  }
  EXPECT_GE(pairs, 1) << "history too short to show the convergence order";
}

class BothBackends : public ::testing::TestWithParam<std::string> {};

TEST_P(BothBackends, SolvesRosenbrockQuadratically) {
  NewtonOptions o;
  o.residual_tolerance = 1e-13;
  auto newton = make_corrector(GetParam(), o);
  Rosenbrock p;
  Vector x(2);
  x << -1.2, 1.0;
  const NewtonSummary s = newton->solve(p, x);
  ASSERT_TRUE(s.converged()) << s.message;
  // Root (1, 1); J is well conditioned there (cond ~ 22), so |dx| <~ 22 * 1e-13.
  EXPECT_NEAR(x[0], 1.0, 1e-11);
  EXPECT_NEAR(x[1], 1.0, 1e-11);
  EXPECT_LE(s.final_residual(), 1e-13);
  EXPECT_EQ(s.residual_history.size(), static_cast<std::size_t>(s.iterations) + 1);
  EXPECT_GE(s.residual_evaluations, s.iterations + 1);
  EXPECT_GE(s.jacobian_evaluations, s.iterations);
  EXPECT_GE(s.seconds, 0.0);
}

TEST_P(BothBackends, SolvesCircleLineQuadratically) {
  NewtonOptions o;
  o.residual_tolerance = 1e-14;
  auto newton = make_corrector(GetParam(), o);
  CircleLine p;
  Vector x(2);
  x << 3.0, 0.2;
  const NewtonSummary s = newton->solve(p, x);
  ASSERT_TRUE(s.converged()) << s.message;
  EXPECT_NEAR(x[0], std::sqrt(0.5), 1e-13);
  EXPECT_NEAR(x[1], std::sqrt(0.5), 1e-13);
  expect_quadratic(s.residual_history);
}

TEST_P(BothBackends, NanResidualIsAStatusNotAnException) {
  auto newton = make_corrector(GetParam(), {});
  NanBeyondHalf p;
  Vector x(1);
  x << 1.0;  // NaN at the start
  NewtonSummary s;
  ASSERT_NO_THROW(s = newton->solve(p, x));
  EXPECT_EQ(s.status, NewtonStatus::evaluation_failed) << s.message;
}

// atan(x) = 0 from x0 = 1.5: plain Newton overshoots with growing amplitude (1.5, -1.69, 2.32,
// -5.1...) into the region |x| > 3 where this residual is NaN. The line search keeps the
// iterates where ||F|| decreases and converges to 0.
class AtanWithNanTails : public Problem {
 public:
  int num_unknowns() const override { return 1; }
  int num_equations() const override { return 1; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r[0] = std::abs(x[0]) > 3 ? std::nan("") : std::atan(x[0]);
    return EvalStatus::ok;
  }
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override {
    J(0, 0) = 1.0 / (1.0 + x[0] * x[0]);
    return EvalStatus::ok;
  }
};

TEST_P(BothBackends, LineSearchTamesAnOvershootingNewton) {
  auto newton = make_corrector(GetParam(), {});
  AtanWithNanTails p;
  Vector x = Vector::Constant(1, 1.5);
  const NewtonSummary s = newton->solve(p, x);
  ASSERT_TRUE(s.converged()) << s.message;
  EXPECT_NEAR(x[0], 0.0, 1e-10);  // |atan x| <= 1e-10 implies |x| <= ~1e-10
}

TEST(EigenNewton, NanDuringIterationsIsEvaluationFailed) {
  NewtonOptions o;
  o.line_search = false;
  EigenNewton newton(o);
  AtanWithNanTails p;
  Vector x = Vector::Constant(1, 1.5);
  NewtonSummary s;
  ASSERT_NO_THROW(s = newton.solve(p, x));
  EXPECT_EQ(s.status, NewtonStatus::evaluation_failed) << s.message;
  EXPECT_EQ(s.iterations, 3);  // the third iterate, -5.1, is where the residual fails
}

INSTANTIATE_TEST_SUITE_P(Core, BothBackends, ::testing::Values("eigen", "kinsol"));

TEST(NewtonParity, KinsolAndEigenFindTheSameRoot) {
  NewtonOptions o;
  o.residual_tolerance = 1e-14;
  EigenNewton eigen(o);
  KinsolNewton kinsol(o);
  for (const auto& start : {Vector::Constant(2, 3.0), Vector::Constant(2, 0.3)}) {
    CircleLine p;
    Vector xe = start, xk = start;
    ASSERT_TRUE(eigen.solve(p, xe).converged());
    ASSERT_TRUE(kinsol.solve(p, xk).converged());
    // Both stop at ||F||_inf <= 1e-14 with cond(J) ~ 1.4 at the root: they agree to 1e-12.
    EXPECT_LT((xe - xk).norm(), 1e-12) << xe.transpose() << " vs " << xk.transpose();
  }
}

TEST(KinsolNewton, RejectsNonSquareSystemsWithAStatus) {
  KinsolNewton kinsol({});
  Sphere circle(2);
  Vector x(2);
  x << 2.0, 0.1;
  const NewtonSummary s = kinsol.solve(circle, x);
  EXPECT_EQ(s.status, NewtonStatus::linear_solver_failed);
  EXPECT_NE(s.message.find("square"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("1 equations vs 2 unknowns"), std::string::npos) << s.message;
}

TEST(KinsolNewton, KeepsKinsolsFlagName) {
  KinsolNewton kinsol({});
  Rosenbrock p;
  Vector x(2);
  x << -1.2, 1.0;
  const NewtonSummary s = kinsol.solve(p, x);
  EXPECT_NE(s.message.find("KIN_SUCCESS"), std::string::npos) << s.message;
}

TEST(EigenNewton, MinimumNormStepsLandOnTheCircleRadially) {
  // One equation, two unknowns: the minimum-norm Gauss-Newton step is along the gradient, i.e.
  // radial, so the iterates stay on the ray through the start and end at (2, 0.1)/|(2, 0.1)|.
  NewtonOptions o;
  o.residual_tolerance = 1e-14;
  EigenNewton newton(o);
  Sphere circle(2);
  Vector x(2);
  x << 2.0, 0.1;
  const Vector expected = x.normalized();
  const NewtonSummary s = newton.solve(circle, x);
  ASSERT_TRUE(s.converged()) << s.message;
  EXPECT_LT((x - expected).norm(), 1e-13);
  expect_quadratic(s.residual_history);
}

TEST(EigenNewton, RankDeficientJacobianStillSteps) {
  // F = (x^2 + y^2 - 1, 2 (x^2 + y^2 - 1)): two equations, rank-1 Jacobian everywhere. The
  // minimum-norm step ignores the dependent row and converges onto the circle.
  class Doubled : public Problem {
   public:
    int num_unknowns() const override { return 2; }
    int num_equations() const override { return 2; }

   protected:
    EvalStatus compute_residual(const Vector& x, Vector& r) const override {
      const double c = x.squaredNorm() - 1.0;
      r << c, 2.0 * c;
      return EvalStatus::ok;
    }
  } p;
  NewtonOptions o;
  o.rank_cutoff = 1e-6;  // FD Jacobian: the second singular value is ~1e-8, not exactly 0
  EigenNewton newton(o);
  Vector x(2);
  x << 0.3, 1.4;
  const NewtonSummary s = newton.solve(p, x);
  ASSERT_TRUE(s.converged()) << s.message;
  EXPECT_NEAR(x.norm(), 1.0, 1e-10);
}

// minimum_norm_solve: the plain QR where J has full column rank by a margin, the COD where it
// has not; either way the Moore-Penrose solution, here against the exact one from the
// normal equations (full rank, cond 1e3: agreement to cond eps ~ 1e-13, 1e-11 allowed) and
// from the SVD with the tiny value dropped (rank 2 of 3: the minimum-norm solution, 1e-12).
TEST(EigenNewton, MinimumNormSolveIsTheLeastSquaresSolutionAtFullAndLowerRank) {
  Matrix J(5, 3);
  J << 1, 2, 0, 0, 1, 1, 3, 0, 1, 1, 1, 1, 0, 2, 5e-3;
  const Vector b = (Vector(5) << 1, -2, 0.5, 3, 1).finished();
  Vector dx;
  EXPECT_EQ(minimum_norm_solve(J, b, 1e-12, dx), 3);
  const Vector normal = (J.transpose() * J).ldlt().solve(J.transpose() * b);
  EXPECT_LT((dx - normal).norm(), 1e-11 * normal.norm());
  // Column 3 = column 1 + column 2 up to 1e-14: rank 2 at a cut-off of 1e-10.
  Matrix deficient = J;
  deficient.col(2) = J.col(0) + J.col(1) + Vector::Constant(5, 1e-14);
  EXPECT_EQ(minimum_norm_solve(deficient, b, 1e-10, dx), 2);
  const Eigen::JacobiSVD<Matrix> svd(deficient, Eigen::ComputeThinU | Eigen::ComputeThinV);
  Vector inverse = svd.singularValues().cwiseInverse();
  inverse[2] = 0;
  const Vector pinv = svd.matrixV() * inverse.asDiagonal() * svd.matrixU().transpose() * b;
  EXPECT_LT((dx - pinv).norm(), 1e-12 * pinv.norm());
}

TEST(EigenNewton, ZeroJacobianWithoutRootStalls) {
  // F = x^2 + 1 at x = 0: J = 0, so the minimum-norm step is zero; the corrector must say
  // "stalled" rather than loop to max_iterations or divide by zero.
  class NoRoot : public Problem {
   public:
    int num_unknowns() const override { return 1; }
    int num_equations() const override { return 1; }

   protected:
    EvalStatus compute_residual(const Vector& x, Vector& r) const override {
      r[0] = x[0] * x[0] + 1.0;
      return EvalStatus::ok;
    }
    EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override {
      J(0, 0) = 2.0 * x[0];
      return EvalStatus::ok;
    }
  } p;
  EigenNewton newton({});
  Vector x = Vector::Zero(1);
  const NewtonSummary s = newton.solve(p, x);
  EXPECT_EQ(s.status, NewtonStatus::stalled) << s.message;
  EXPECT_EQ(s.iterations, 1);
}

// Chord steps on a nearby Jacobian (newton.hpp, Corrector::solve with nearby_jacobian).

TEST(EigenNewton, NearbyJacobianGivesChordStepsAndTheSameRoot) {
  // Circle-line from (0.8, 0.6): the exact Jacobian at the root (sqrt(1/2), sqrt(1/2)) is the
  // nearby one. Chord steps contract by |J(root)^-1 (J(x) - J(root))| ~ |x - root| ~ 0.01
  // per step, so the solve needs no fresh Jacobian; the root is the same to 1e-13 (the
  // tolerance 1e-14 on F, whose Jacobian is O(1) here).
  NewtonOptions o;
  o.residual_tolerance = 1e-14;
  EigenNewton newton(o);
  CircleLine p;
  const double r = std::sqrt(0.5);
  Matrix at_root(2, 2);
  at_root << 2 * r, 2 * r, -1, 1;
  Vector x(2);
  x << 0.72, 0.70;
  const long jacobians_before = p.counters().jacobians;
  const NewtonSummary s = newton.solve(p, x, at_root);
  ASSERT_TRUE(s.converged()) << s.message;
  EXPECT_NEAR(x[0], r, 1e-13);
  EXPECT_NEAR(x[1], r, 1e-13);
  EXPECT_GT(s.chord_steps, 0);
  EXPECT_EQ(s.chord_steps, s.iterations);
  EXPECT_EQ(p.counters().jacobians, jacobians_before);
  // Each chord step counts a quarter for the step control.
  EXPECT_EQ(s.equivalent_iterations(), (s.chord_steps + 3) / 4);
}

TEST(EigenNewton, APoorNearbyJacobianCostsOneResidualNotTheAnswer) {
  // A nearby Jacobian with the wrong sign of a row: the first chord step grows ||F||, so the
  // solve takes a fresh Jacobian at once and converges quadratically to the same root as a
  // solve without one.
  NewtonOptions o;
  o.residual_tolerance = 1e-14;
  EigenNewton newton(o);
  CircleLine p;
  Matrix wrong(2, 2);
  wrong << 2.0, 2.0, 1.0, -1.0;
  Vector x(2), plain(2);
  x << 3.0, 0.2;
  plain = x;
  const NewtonSummary seeded = newton.solve(p, x, wrong);
  const NewtonSummary fresh = newton.solve(p, plain);
  ASSERT_TRUE(seeded.converged()) << seeded.message;
  EXPECT_EQ(seeded.chord_steps, 0);
  EXPECT_NEAR(x[0], plain[0], 1e-14);
  EXPECT_NEAR(x[1], plain[1], 1e-14);
  // The rejected chord step is the only extra residual.
  EXPECT_EQ(seeded.residual_evaluations, fresh.residual_evaluations + 1);
  EXPECT_EQ(seeded.jacobian_evaluations, fresh.jacobian_evaluations);
}

// The solve with `nearby` takes the same path, bit for bit, as the one without.
void expect_nearby_ignored(Corrector& corrector, const Matrix& nearby) {
  CircleLine p;
  Vector x(2), plain(2);
  x << 3.0, 0.2;
  plain = x;
  const NewtonSummary seeded = corrector.solve(p, x, nearby);
  const NewtonSummary fresh = corrector.solve(p, plain);
  EXPECT_EQ(seeded.chord_steps, 0);
  EXPECT_EQ(seeded.residual_evaluations, fresh.residual_evaluations);
  EXPECT_EQ(x, plain);
}

TEST(EigenNewton, NearbyJacobianOfTheWrongSizeIsIgnored) {
  EigenNewton newton({});
  expect_nearby_ignored(newton, Matrix::Identity(3, 2));
}

TEST(KinsolNewton, IgnoresANearbyJacobian) {
  KinsolNewton newton({});
  expect_nearby_ignored(newton, Matrix::Identity(2, 2));
}

}  // namespace
}  // namespace backbone::core
