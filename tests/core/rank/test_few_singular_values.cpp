// core/few_singular_values against exact oracles: A = U diag(s) V^T with U, V orthonormal factors
// of seeded Gaussian matrices and chosen s, so that every singular value and vector is known.
// The tolerances follow from each solver's own stopping rule (commented at each test) plus
// round-off of order eps |A| = 2.2e-16 sigma_max, with a margin of 10 or more.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/rank/few_singular_values.hpp"

namespace backbone::core {
namespace {

// An m x k matrix with orthonormal columns: the Q of a seeded Gaussian matrix.
Matrix random_orthonormal(Eigen::Index m, Eigen::Index k, unsigned seed) {
  std::mt19937 engine(seed);
  std::normal_distribution<double> normal;
  Matrix G(m, k);
  for (Eigen::Index j = 0; j < k; ++j)
    for (Eigen::Index i = 0; i < m; ++i) G(i, j) = normal(engine);
  const Eigen::HouseholderQR<Matrix> qr(G);
  return qr.householderQ() * Matrix::Identity(m, k);
}

// U diag(s) V^T, m x s.size(), with its factors.
struct Oracle {
  Matrix U, V, A;
  Vector s;
};
Oracle with_singular_values(Eigen::Index m, const Vector& s, unsigned seed) {
  Oracle o;
  o.s = s;
  o.U = random_orthonormal(m, s.size(), seed);
  o.V = random_orthonormal(s.size(), s.size(), seed + 1);
  o.A = o.U * s.asDiagonal() * o.V.transpose();
  return o;
}

// The sine of the largest principal angle between the spans of X and Y (orthonormal columns).
double span_distance(const Matrix& X, const Matrix& Y) {
  return (Y - X * (X.transpose() * Y)).colwise().norm().maxCoeff();
}

// Descending from 10 to 1e-2, then `tail` (descending, below the rest).
Vector spectrum(Eigen::Index n, const Vector& tail) {
  Vector s(n);
  const Eigen::Index head = n - tail.size();
  for (Eigen::Index i = 0; i < head; ++i)
    s[i] = 10 * std::pow(1e-3, static_cast<double>(i) / static_cast<double>(head - 1));
  s.tail(tail.size()) = tail;
  return s;
}

TEST(SmallestSingularTriplet, FindsTheSmallestTripletOfAKnownMatrix) {
  // sigma_min = 1e-4, the next 1e-2. Stopping rule: |R^T u - sigma v| <= 1e-4 sigma + 1e-12 |A|_F
  // puts a singular value within 1e-8 + 4e-11 of sigma, and only sigma_min is that close; the
  // right vector's angle to v_min is at most that residual over the gap to the next value
  // (Davis-Kahan): 1e-8 / 1e-2 = 1e-6.
  const Oracle o = with_singular_values(60, spectrum(30, Vector::Constant(1, 1e-4)), 11);
  Vector left, right;
  double sigma = 0;
  ASSERT_TRUE(smallest_singular_triplet(o.A, Vector(), left, right, sigma));
  EXPECT_NEAR(sigma, 1e-4, 1e-4 * 1e-4 + 1e-12 * o.A.norm());
  EXPECT_NEAR(right.norm(), 1.0, 1e-14);
  EXPECT_LT(1 - std::abs(right.dot(o.V.col(29))), 1e-10);  // 1 - cos = sin^2 / 2 <= 5e-13
  EXPECT_LT(span_distance(o.V.col(29), right), 1e-6);
  // left = A v / sigma: along u_min, unit to the same accuracy.
  EXPECT_LT(span_distance(o.U.col(29), left), 1e-6);
  EXPECT_NEAR(left.norm(), 1.0, 1e-6);
}

TEST(SmallestSingularTriplet, FromTheExactRightVectorOneVectorSuffices) {
  // Started on v_min, the first basis vector is v_min to round-off and the residual test passes
  // at once: the triplet is exact to eps |A| / sigma_min = 2e-16 * 10 / 1e-4 = 2e-11.
  const Oracle o = with_singular_values(40, spectrum(20, Vector::Constant(1, 1e-4)), 21);
  Vector left, right;
  double sigma = 0;
  ASSERT_TRUE(smallest_singular_triplet(o.A, Vector(o.V.col(19)), left, right, sigma));
  EXPECT_NEAR(sigma, 1e-4, 1e-4 * 1e-9);
  EXPECT_LT(span_distance(o.V.col(19), right), 1e-9);
}

TEST(SmallestSingularTriplet, FalseForAWideOrSingularMatrix) {
  Vector left, right;
  double sigma = 0;
  EXPECT_FALSE(smallest_singular_triplet(Matrix::Ones(3, 5), Vector(), left, right, sigma));
  EXPECT_FALSE(smallest_singular_triplet(Matrix(0, 0), Vector(), left, right, sigma));
  Matrix singular = Matrix::Identity(6, 4);
  singular.col(3).setZero();  // a zero pivot of R
  EXPECT_FALSE(smallest_singular_triplet(singular, Vector(), left, right, sigma));
}

TEST(SmallestSingularValues, LargestAndTheValuesBelowTheThresholdWithTheirSpan) {
  // 80 x 40; three values below the threshold 1e-8 * 10 = 1e-7, the rest from 10 down to 1e-2.
  // Stopping rules: sigma_max's Lanczos estimate moved by at most 1e-10 of itself (an estimate
  // from below that converges much faster than that near a separated top: 1e-12 relative), the
  // span of the values below the threshold by a sine of 1e-10, the smallest kept value by 1e-10
  // of itself, each step shrinking the error by (s / sigma_{k+1})^2 < 1/4. The small values'
  // absolute round-off is eps sigma_max = 2e-15.
  Vector tail(3);
  tail << 1e-9, 1e-10, 1e-12;
  const Oracle o = with_singular_values(80, spectrum(40, tail), 31);
  SmallestSingularValues few;
  ASSERT_TRUE(smallest_singular_values(o.A, 1e-8, 0.0, few));
  EXPECT_NEAR(few.largest, 10.0, 10.0 * 1e-10);
  const Eigen::Index k = few.values.size();
  ASSERT_EQ(k, 8);  // the first block: three below the threshold leave it one above
  ASSERT_EQ(few.right.rows(), 40);
  ASSERT_EQ(few.right.cols(), k);
  // The stopping rule holds the values below the threshold and the smallest above it (entry
  // k - 4); the larger ones of the block are Ritz values still on their way (not asserted).
  for (Eigen::Index i = k - 4; i < k; ++i) {
    const double exact = o.s[40 - k + i];
    EXPECT_NEAR(few.values[i], exact, 1e-9 * exact + 1e-13) << i;
  }
  // The three below the threshold: their span is v_38..v_40's.
  EXPECT_LT(span_distance(o.V.rightCols(3), few.right.rightCols(3)), 1e-8);
  EXPECT_LT((few.right.transpose() * few.right - Matrix::Identity(k, k)).norm(), 1e-13);
}

TEST(SmallestSingularValues, TheBlockDoublesWhileTheValuesBelowFillIt) {
  // Nine below the threshold fill the first block of 8: the block doubles to 16.
  const Vector tail = Vector::LinSpaced(9, 1e-9, 1e-10);
  const Oracle o = with_singular_values(90, spectrum(40, tail), 41);
  SmallestSingularValues few;
  ASSERT_TRUE(smallest_singular_values(o.A, 1e-8, 0.0, few));
  ASSERT_EQ(few.values.size(), 16);
  EXPECT_LT(span_distance(o.V.rightCols(9), few.right.rightCols(9)), 1e-8);
  EXPECT_NEAR(few.values[6], o.s[30], 1e-9 * o.s[30]);  // the smallest above the threshold
}

// The same sparse matrix with two dense rows appended (rows with an entry in every column, as
// the contact bar's exact Jacobian has where a front's motion depends on every unknown): the
// sparse path sets them apart (Woodbury) and must agree with the full SVD of that J.
TEST(SmallestSingularValues, ASparseMatrixWithDenseRowsAgreesWithTheFullSvd) {
  const Eigen::Index n = 64;
  Vector tail(2);
  tail << 1e-9, 1e-11;
  const Vector s = spectrum(n, tail);
  Matrix J = Matrix::Zero(2 * n + 2, n);
  for (Eigen::Index j = 0; j < n; ++j) J(2 * j, j) = (j % 3 ? -1.0 : 1.0) * s[j];
  for (Eigen::Index j = 0; j < n; ++j) {  // dense, but none along e_62, e_63
    J(2 * n, j) = j < n - 2 ? std::sin(0.3 * j + 0.1) : 0.0;
    J(2 * n + 1, j) = j < n - 2 ? std::cos(0.7 * j) : 0.0;
  }
  const Eigen::JacobiSVD<Matrix> full(J, Eigen::ComputeThinV);
  SmallestSingularValues few;
  ASSERT_TRUE(smallest_singular_values(J, 1e-8, 0.0, few));
  EXPECT_NEAR(few.largest, full.singularValues()[0], 1e-10 * full.singularValues()[0]);
  EXPECT_LT(span_distance(full.matrixV().rightCols(2), few.right.rightCols(2)), 1e-8);
  // The smallest value above the threshold: the shift's 5e-6 relative as in the test below.
  const Eigen::Index k = few.values.size();
  EXPECT_NEAR(few.values[k - 3], full.singularValues()[n - 3], 1e-5 * full.singularValues()[n - 3]);
}

TEST(SmallestSingularValues, ASparseMatrixTakesTheSparsePathToTheSameAnswer) {
  // A signed permutation of rows times a diagonal (orthogonal factors that keep J sparse: one
  // entry per row, 128 x 64), so that the sparse Cholesky path answers. Its shift of 1e-10 of
  // the largest diagonal entry of J^T J moves the smallest values by at most
  // 1e-10 sigma_max^2 / (2 sigma) in sigma^2 terms; for the values 1e-3 and above, 1e-10 * 100 /
  // 1e-3 / 2 = 5e-6 relative, and not the span of the values below the threshold.
  const Eigen::Index n = 64;
  Vector tail(2);
  tail << 1e-9, 1e-11;
  const Vector s = spectrum(n, tail);
  Matrix J = Matrix::Zero(2 * n, n);
  std::mt19937 engine(51);
  std::vector<Eigen::Index> rows(2 * n);
  for (Eigen::Index i = 0; i < 2 * n; ++i) rows[static_cast<std::size_t>(i)] = i;
  std::shuffle(rows.begin(), rows.end(), engine);
  for (Eigen::Index j = 0; j < n; ++j)
    J(rows[static_cast<std::size_t>(j)], j) = (j % 2 ? -1.0 : 1.0) * s[j];
  SmallestSingularValues few;
  ASSERT_TRUE(smallest_singular_values(J, 1e-8, 0.0, few));
  EXPECT_NEAR(few.largest, 10.0, 10.0 * 1e-10);
  // The two below the threshold are e_62 and e_63.
  EXPECT_LT(span_distance(Matrix::Identity(n, n).rightCols(2), few.right.rightCols(2)), 1e-8);
  // The smallest above the threshold (the one the stopping rule holds besides the span).
  const Eigen::Index k = few.values.size();
  EXPECT_NEAR(few.values[k - 3], s[n - 3], 1e-5 * s[n - 3]);
}

TEST(SmallestSingularValues, FalseWhereItCannotAnswer) {
  SmallestSingularValues few;
  EXPECT_FALSE(smallest_singular_values(Matrix::Ones(3, 5), 1e-8, 0.0, few));      // wide
  EXPECT_FALSE(smallest_singular_values(Matrix::Identity(3, 3), 1e-8, 0.0, few));  // n < 4
  // Half the values below the threshold: the block would exceed n / 2.
  Vector tail = Vector::Constant(10, 1e-12);
  const Oracle o = with_singular_values(30, spectrum(20, tail), 61);
  EXPECT_FALSE(smallest_singular_values(o.A, 1e-8, 0.0, few));
}

TEST(LeadingRightSingular, TheLeadingValuesAndVectorsWhereTheyStandAboveTheRest) {
  // 1e4, 5e3, 1e3 above a rest of at most 1: three steps of subspace iteration on A^T A with a
  // block of 6 shrink the angle to v_i by (sigma_7 / sigma_i)^6 <= (1 / 1e3)^6 = 1e-18 (from a
  // start not orthogonal to them), so the vectors are exact to round-off (eps |A| / gap = 2e-16 *
  // 1e4 / 2e3 ~ 1e-15) and the values to eps sigma_1.
  Vector s = Vector::LinSpaced(30, 1.0, 1e-2);
  s.head(3) << 1e4, 5e3, 1e3;
  const Oracle o = with_singular_values(50, s, 71);
  Vector sigma;
  Matrix right;
  leading_right_singular(o.A, 3, sigma, right);
  ASSERT_EQ(sigma.size(), 3);
  ASSERT_EQ(right.rows(), 30);
  ASSERT_EQ(right.cols(), 3);
  for (Eigen::Index i = 0; i < 3; ++i) {
    EXPECT_NEAR(sigma[i], s[i], 1e-12 * s[0]) << i;
    EXPECT_LT(span_distance(o.V.col(i), right.col(i)), 1e-10) << i;
  }
}

TEST(LeadingRightSingular, NeverMoreThanTheMatrixHas) {
  // count + 3 exceeds the 4 columns: the block is all of them, and count values come back.
  const Oracle o = with_singular_values(6, (Vector(4) << 4, 3, 2, 1).finished(), 81);
  Vector sigma;
  Matrix right;
  leading_right_singular(o.A, 2, sigma, right);
  ASSERT_EQ(sigma.size(), 2);
  EXPECT_NEAR(sigma[0], 4.0, 1e-13);
  EXPECT_NEAR(sigma[1], 3.0, 1e-13);
}

}  // namespace
}  // namespace backbone::core
