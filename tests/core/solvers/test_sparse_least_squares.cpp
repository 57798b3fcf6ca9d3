// SparseLeastSquares (core/solvers/sparse_least_squares.hpp) against a dense Householder QR and the
// SVD, on matrices shaped like the contact bar's bordered shooting Jacobian: sparse rows, one
// dense column, one dense row.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <random>

#include "core/rank/rank_report.hpp"
#include "core/solvers/eigen_newton.hpp"
#include "core/solvers/sparse_least_squares.hpp"

namespace {

using backbone::core::Matrix;
using backbone::core::SparseLeastSquares;
using backbone::core::Vector;

// m x n: rows i and i + n/2... of ~7 entries (a band and a folded image, like the bar's), a
// dense last column, and, with `bordered`, a dense last row. Fixed seed.
Matrix shooting_like(int m, int n, bool bordered, unsigned seed = 7) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Matrix J = Matrix::Zero(m, n);
  const int rows = bordered ? m - 1 : m;
  for (int i = 0; i < rows; ++i) {
    const int a = (i / 2) % (n - 1), b = (n - 2 - i / 2 + 3 * n) % (n - 1);
    for (int d = -1; d <= 1; ++d) {
      J(i, (a + d + n - 1) % (n - 1)) += 1 + u(gen);
      J(i, (b + d + n - 1) % (n - 1)) += 0.5 * u(gen);
    }
    J(i, n - 1) = u(gen);
  }
  if (bordered)
    for (int j = 0; j < n; ++j) J(m - 1, j) = u(gen);
  return J;
}

TEST(SparseLeastSquares, MatchesTheHouseholderSolutionOfAnInconsistentSystem) {
  const Matrix J = shooting_like(201, 100, true);
  const Vector b = Vector::LinSpaced(201, -1, 2).array().sin();  // not in J's range
  SparseLeastSquares ls;
  ASSERT_TRUE(ls.compute(J, 1e-12));
  Vector x;
  ASSERT_TRUE(ls.solve(b, x));
  const Eigen::HouseholderQR<Matrix> qr(J);
  const Vector reference = qr.solve(b);
  // Both are least-squares solutions to about cond(J) eps (cond ~ 1e2 here) and the iteration
  // stops at 1e-11 of J^T b in the normal residual.
  EXPECT_LT((x - reference).norm(), 1e-9 * reference.norm());
  EXPECT_LT((J.transpose() * (J * x - b)).norm(), 1e-10 * (J.transpose() * b).norm());
}

TEST(SparseLeastSquares, ADenseRowFixesTheNullDirectionOfTheSparseRows) {
  // On a branch the sparse rows (F's Jacobian) have a null vector t and the arclength row t^T
  // removes it: the sparse rows' normal matrix is singular, J is not. Here t is dense and the
  // dense column is chosen so that F t = 0.
  Matrix J = shooting_like(201, 100, true);
  const Vector t = Vector::LinSpaced(100, 1, 2).normalized();
  J.block(0, 99, 200, 1) = -J.block(0, 0, 200, 99) * t.head(99) / t[99];
  J.row(200) = t.transpose();
  ASSERT_LT((J.topRows(200) * t).norm(), 1e-13 * J.norm());
  const Vector b = J * Vector::LinSpaced(100, 0, 1);  // consistent
  SparseLeastSquares ls;
  ASSERT_TRUE(ls.compute(J, 1e-12));
  Vector x;
  ASSERT_TRUE(ls.solve(b, x));
  EXPECT_LT((x - Vector::LinSpaced(100, 0, 1)).norm(), 1e-9 * Vector::LinSpaced(100, 0, 1).norm());
}

TEST(SparseLeastSquares, RefusesWhatTheDensePathDoesBetter) {
  SparseLeastSquares ls;
  // Too small to pay: the dense QR keeps every small problem bit for bit as before.
  EXPECT_FALSE(ls.compute(shooting_like(41, 20, true), 1e-12));
  // Dense.
  EXPECT_FALSE(ls.compute(Matrix::Ones(200, 100) + Matrix::Identity(200, 100), 1e-12));
  // Rank deficient: the minimum-norm solution is not the normal equations' (a column repeated).
  Matrix deficient = shooting_like(201, 100, true);
  deficient.col(5) = deficient.col(6);
  EXPECT_FALSE(ls.compute(deficient, 1e-12));
  // Conditioned worse than the cut-off allows: sigma_min ~ 1e-6 sigma_max against 1e-5.
  Matrix graded = shooting_like(201, 100, true);
  graded.col(3) *= 1e-6;
  EXPECT_FALSE(ls.compute(graded, 1e-5));
  EXPECT_TRUE(ls.compute(shooting_like(201, 100, true), 1e-5));
}

// Damped (SparseLeastSquares::compute, damped = true; the rank verification's probes): a
// rank-deficient J that the exact path refuses is kept, and the solution is that of the damped
// normal equations (J^T J + mu I) x = J^T b, mu = 1e-10 of the largest diagonal entry of the
// sparse rows' normal matrix, here solved densely by Cholesky as the oracle. J has three exact
// null directions (a column repeated, one doubled, one negated, the dense row too) and one
// column scaled by 1e-7, whose small singular value the damping suppresses where the
// minimum-norm solution would divide by it: the damped solution has no component along the
// null directions, and for a consistent b in the span of the well-conditioned columns it
// reproduces b to about mu / sigma^2 of their smallest singular value (~1e-6 relative here).
TEST(SparseLeastSquares, DampedKeepsARankDeficientJacobianAndSolvesTheDampedNormalEquations) {
  Matrix J = shooting_like(201, 100, true, 5);
  J.col(10) = J.col(11);
  J.col(40) = 2 * J.col(41);
  J.col(70) = -J.col(72);
  J.col(3) *= 1e-7;  // sigma ~ 1e-7 sigma_max: damped (sigma / mu), not inverted (1 / sigma)
  SparseLeastSquares ls;
  EXPECT_FALSE(ls.compute(J, 1e-12));
  ASSERT_TRUE(ls.compute(J, 1e-12, true));
  EXPECT_TRUE(ls.is_damped());
  const Matrix sparse_rows = J.topRows(200);
  const double mu = 1e-10 * (sparse_rows.transpose() * sparse_rows).diagonal().maxCoeff();
  const Matrix damped = J.transpose() * J + mu * Matrix::Identity(100, 100);
  const Vector b = Vector::LinSpaced(201, -1, 2).array().sin();
  Vector x;
  ASSERT_TRUE(ls.solve(b, x));
  const Vector reference = damped.llt().solve(J.transpose() * b);
  // The iteration stops at 1e-11 of J^T b in the (damped) normal residual; the damped matrix
  // is conditioned like J^T J on the kept part (~1e4 here), so x is within ~1e-7 of it.
  EXPECT_LT((x - reference).norm(), 1e-6 * reference.norm());
  Matrix null(100, 3);
  null.setZero();
  null(10, 0) = 1;
  null(11, 0) = -1;
  null(40, 1) = 1;
  null(41, 1) = -2;
  null(70, 2) = 1;
  null(72, 2) = 1;
  ASSERT_LT((J * null).norm(), 1e-13 * J.norm());
  // Along the null directions J^T b holds only its round-off, eps |J| |b|, which the damping
  // divides by mu = 1e-10 |J|^2: at most ~eps / 1e-10 = 2e-6 of x (measured 3e-8; the dense
  // oracle's own is 1.5e-7).
  EXPECT_LT((null.transpose() * x).norm(), 1e-5 * x.norm());
  Vector kept = Vector::LinSpaced(100, 0, 1);
  kept[3] = 0;
  kept -= null * (null.transpose() * null).ldlt().solve(null.transpose() * kept);
  Vector y;
  ASSERT_TRUE(ls.solve(J * kept, y));
  EXPECT_LT((J * y - J * kept).norm(), 1e-6 * (J * kept).norm());
}

// A cut-off far above the normal equations' floor (the tangent's, the rank threshold) with
// sigma_min between 1.25 and 2 times it: two inverse-iteration steps cannot tell it from below
// the cut-off by their margin, the settled estimate can, and the solution is the full-rank
// least-squares one (the SVD's). Below 1.25 times it the dense path keeps its say.
TEST(SparseLeastSquares, ASettledEstimateBetweenTheCutoffAndTwiceItIsKept) {
  Matrix J = shooting_like(201, 100, true, 9);
  J.col(3) *= 1e-4;
  const Eigen::JacobiSVD<Matrix> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
  double largest_column = 0;
  for (Eigen::Index j = 0; j < J.cols(); ++j)
    largest_column = std::max(largest_column, J.col(j).norm());
  const double ratio = svd.singularValues().tail(1)[0] / largest_column;
  // A clear gap to the next value, so that the estimate settles at sigma_min.
  ASSERT_LT(svd.singularValues().tail(1)[0], 0.2 * svd.singularValues().tail(2)[0]);
  SparseLeastSquares ls;
  ASSERT_TRUE(ls.compute(J, ratio / 1.6));
  EXPECT_FALSE(ls.is_damped());
  const Vector b = Vector::LinSpaced(201, -1, 2).array().sin();
  Vector x;
  ASSERT_TRUE(ls.solve(b, x));
  const Vector reference = svd.solve(b);
  // cond(J) ~ 1 / ratio (~1e4 here): the iteration's cond(J) eps, with a margin.
  EXPECT_LT((x - reference).norm(), 1e-8 * reference.norm());
  EXPECT_FALSE(ls.compute(J, ratio / 1.1));
}

TEST(SparseLeastSquares, MinimumNormSolveTakesItAndAgreesWithTheSvd) {
  const Matrix J = shooting_like(301, 150, true, 11);
  const Vector b = Vector::LinSpaced(301, 0, 3).array().cos();
  Vector dx;
  EXPECT_EQ(backbone::core::minimum_norm_solve(J, b, 1e-12, dx), 150);
  const Eigen::JacobiSVD<Matrix> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Vector pinv = svd.solve(b);
  EXPECT_LT((dx - pinv).norm(), 1e-9 * pinv.norm());
}

// The rank report of a sparse J without dense rows takes no QR (rank_report.cpp, SparseGram):
// against the full SVD on a shooting-like J with three exact null directions (repeated and
// scaled columns). The kept values come from Rayleigh-Ritz with J itself: within 1e-10 of the
// SVD's (round-off of J X plus the inverse iteration's span error, eps ||J|| / gap ~ 1e-13 at
// the gap here); the null span to 1e-9 like the dense path's test (test_rank_report.cpp).
TEST(SparseLeastSquares, TheRankReportOfASparseJacobianAgreesWithTheSvd) {
  Matrix J = shooting_like(199, 100, false);
  J.col(10) = J.col(11);
  J.col(40) = 2 * J.col(41);
  J.col(70) = -J.col(72);
  backbone::core::RankOptions options;
  options.full_spectrum = false;
  options.relative_threshold = 1e-5;
  const backbone::core::RankReport r = backbone::core::rank_report(J, options);
  const Eigen::JacobiSVD<Matrix> svd(J, Eigen::ComputeFullV);
  const Vector& s = svd.singularValues();
  ASSERT_EQ(r.nullity, 3);
  EXPECT_EQ(r.rank, 97);
  EXPECT_NEAR(r.singular_values[0], s[0], 1e-9 * s[0]);
  EXPECT_NEAR(r.singular_values[96], s[96], 1e-10 * s[0]);
  for (int i = 97; i < 100; ++i) EXPECT_LT(r.singular_values[i], 1e-10 * s[0]) << i;
  const Matrix exact = svd.matrixV().rightCols(3) * svd.matrixV().rightCols(3).transpose();
  const Matrix& N = r.null_directions;
  EXPECT_LT((N * N.transpose() - exact).norm(), 1e-9);
}

}  // namespace
