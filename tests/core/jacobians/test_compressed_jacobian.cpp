// The compressed (Curtis-Powell-Reid) finite-difference Jacobian of core/compressed_jacobian on
// an "arrow" system with a known analytic Jacobian: tridiagonal plus one dense column,
//     F_i(x) = x_i^2 + sin(x_{i+1}) - x_{i-1} + x_n x_i / 2   (i = 0..n-1, x_{-1} = x_n = ...),
// unknowns x_0..x_n (x_n the dense column, like a period). Each F_i reads only x_{i-1}, x_i,
// x_{i+1} and x_n, so with the right pattern every compressed entry is computed from exactly
// the floating-point values the column-by-column difference uses: the two agree bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/errors.hpp"
#include "core/jacobians/compressed_jacobian.hpp"
#include "core/jacobians/finite_difference.hpp"

namespace {

using namespace backbone::core;

class Arrow : public Problem {
 public:
  explicit Arrow(int n, bool drop_superdiagonal = false, bool declare = true)
      : n_(n), drop_(drop_superdiagonal), declare_(declare) {}
  int num_unknowns() const override { return n_ + 1; }
  int num_equations() const override { return n_; }
  Matrix analytic(const Vector& x) const {
    Matrix J = Matrix::Zero(n_, n_ + 1);
    for (int i = 0; i < n_; ++i) {
      J(i, i) = 2 * x[i] + 0.5 * x[n_];
      if (i + 1 < n_) J(i, i + 1) = std::cos(x[i + 1]);
      if (i > 0) J(i, i - 1) = -1;
      J(i, n_) = 0.5 * x[i];
    }
    return J;
  }
  JacobianPattern pattern() const {
    JacobianPattern p;
    p.row_columns.resize(static_cast<std::size_t>(n_));
    for (int i = 0; i < n_; ++i)
      for (int j = i - 1; j <= i + 1; ++j)
        if (j >= 0 && j < n_ && !(drop_ && j == i + 1))
          p.row_columns[static_cast<std::size_t>(i)].push_back(j);
    p.dense_columns = {n_};
    return p;
  }
  std::optional<JacobianPattern> jacobian_pattern(const Vector&) const override {
    if (!declare_) return std::nullopt;
    return pattern();
  }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    for (int i = 0; i < n_; ++i)
      r[i] = x[i] * x[i] + (i + 1 < n_ ? std::sin(x[i + 1]) : 0.0) - (i > 0 ? x[i - 1] : 0.0) +
             0.5 * x[n_] * x[i];
    return EvalStatus::ok;
  }

 private:
  int n_;
  bool drop_, declare_;
};

Vector point(int n) {
  Vector x(n + 1);
  for (int j = 0; j <= n; ++j) x[j] = 0.3 + 0.7 * std::sin(1.3 * j);
  return x;
}

TEST(CompressedJacobian, MatchesTheAnalyticJacobianWithFourResidualsForTheColumns) {
  const int n = 40;
  Arrow arrow(n);
  const Vector x = point(n);
  Matrix J;
  CompressedJacobianReport report;
  ASSERT_EQ(compressed_finite_difference_jacobian(arrow, x, arrow.pattern(), J, {}, &report),
            EvalStatus::ok);
  // Tridiagonal columns need 3 colours, the dense column its own: 4 residuals instead of 41,
  // plus F(x) and the check.
  EXPECT_EQ(report.colours, 4);
  EXPECT_EQ(report.residuals, 6);
  EXPECT_FALSE(report.fell_back);
  EXPECT_LT(report.check_error, 1.0);
  // Forward differences: truncation h |F''| / 2 with h = 1.5e-8 max(|x_j|, 1) and |F''| <= 2,
  // plus round-off eps |F| / h ~ 1e-8: 1e-6 leaves a wide margin and is far below any entry.
  EXPECT_LT((J - arrow.analytic(x)).cwiseAbs().maxCoeff(), 1e-6);
  // The right pattern reads every entry from the same floating-point values as column by column.
  Matrix dense;
  ASSERT_EQ(finite_difference_jacobian(arrow, x, dense), EvalStatus::ok);
  EXPECT_EQ((J - dense).cwiseAbs().maxCoeff(), 0.0);
}

TEST(CompressedJacobian, CentralDifferencesMatchTheAnalyticJacobian) {
  Arrow arrow(12);
  const Vector x = point(12);
  FiniteDifferenceOptions central;
  central.scheme = FiniteDifferenceOptions::Scheme::central;
  Matrix J;
  CompressedJacobianReport report;
  ASSERT_EQ(compressed_finite_difference_jacobian(arrow, x, arrow.pattern(), J, central, &report),
            EvalStatus::ok);
  EXPECT_FALSE(report.fell_back);
  EXPECT_EQ(report.residuals, 1 + 2 * (4 + 1));
  // Central: truncation h^2 |F'''| / 6 with h = 6e-6 and |F'''| <= 1, round-off eps / h ~ 4e-11.
  EXPECT_LT((J - arrow.analytic(x)).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(CompressedJacobian, ThreadsGiveTheOneThreadJacobianBitForBit) {
  Arrow arrow(60);
  const Vector x = point(60);
  Matrix one;
  ASSERT_EQ(compressed_finite_difference_jacobian(arrow, x, arrow.pattern(), one), EvalStatus::ok);
  for (int threads : {2, 3, 8}) {
    FiniteDifferenceOptions options;
    options.threads = threads;
    Matrix many;
    ASSERT_EQ(compressed_finite_difference_jacobian(arrow, x, arrow.pattern(), many, options),
              EvalStatus::ok);
    EXPECT_EQ((many - one).cwiseAbs().maxCoeff(), 0.0) << threads << " threads";
  }
}

// The compressed Jacobian of `problem` at x from its own pattern, with its report.
CompressedJacobianReport compress(const Arrow& problem, const Vector& x, Matrix& J) {
  CompressedJacobianReport report;
  EXPECT_EQ(compressed_finite_difference_jacobian(problem, x, problem.pattern(), J, {}, &report),
            EvalStatus::ok);
  return report;
}

TEST(CompressedJacobian, ACorrectorsScopeLoosensTheCheckAndEndsWithIt) {
  // The check error is |(J p)_i - d_i| / (tau (size_i + floor)): at the corrector's tau it is
  // the strict one times 1e-3 / tau, exactly the same differences. Dropping the superdiagonal
  // gives errors of e > 1 at the default tau 1e-3 (the test below); a scope of 2 e 1e-3 accepts
  // that Jacobian as it is (no fallback, the dropped entries missing), one of e 1e-3 / 2 does not,
  // and a nested scope of 0 brings the pattern's own back.
  const Arrow wrong(20, /*drop_superdiagonal=*/true);
  const Vector x = point(20);
  Matrix J;
  const CompressedJacobianReport strict = compress(wrong, x, J);
  ASSERT_TRUE(strict.fell_back);
  const double e = strict.check_error;
  ASSERT_GT(e, 2.0);  // (about 1.6e3 here: the scopes below are loose beyond use, but exact)
  EXPECT_EQ(CorrectorJacobians::tolerance(), 0.0);
  {
    const CorrectorJacobians loose(2 * e * 1e-3);
    const CompressedJacobianReport accepted = compress(wrong, x, J);
    EXPECT_FALSE(accepted.fell_back);
    EXPECT_NEAR(accepted.check_error, 0.5, 1e-12);
    EXPECT_EQ(J(0, 1), 0.0);  // the dropped entry stays dropped
    {
      const CorrectorJacobians own(0);
      EXPECT_TRUE(compress(wrong, x, J).fell_back);
    }
    EXPECT_DOUBLE_EQ(CorrectorJacobians::tolerance(), 2 * e * 1e-3);
  }
  {
    const CorrectorJacobians not_enough(0.5 * e * 1e-3);
    EXPECT_TRUE(compress(wrong, x, J).fell_back);
  }
  EXPECT_EQ(CorrectorJacobians::tolerance(), 0.0);
}

TEST(CompressedJacobian, AStructuralPatternIsKeptInACorrectorsScopeOnly) {
  // The same failing check (the dropped superdiagonal, error e >> 1 at any scope below e 1e-3):
  // outside a corrector's scope a pattern declared structural still falls back column by
  // column; inside one its J is kept as it is, flagged, with the check's error reported.
  const Arrow wrong(20, /*drop_superdiagonal=*/true);
  const Vector x = point(20);
  JacobianPattern pattern = wrong.pattern();
  pattern.structural = true;
  Matrix J;
  CompressedJacobianReport report;
  ASSERT_EQ(compressed_finite_difference_jacobian(wrong, x, pattern, J, {}, &report),
            EvalStatus::ok);
  EXPECT_TRUE(report.fell_back);
  EXPECT_FALSE(report.kept_unchecked);
  EXPECT_NE(J(0, 1), 0.0);
  const double e = report.check_error;
  ASSERT_GT(e, 2.0);
  {
    const CorrectorJacobians loose(0.5 * e * 1e-3);  // not enough to pass the check
    ASSERT_EQ(compressed_finite_difference_jacobian(wrong, x, pattern, J, {}, &report),
              EvalStatus::ok);
    EXPECT_FALSE(report.fell_back);
    EXPECT_TRUE(report.kept_unchecked);
    EXPECT_NEAR(report.check_error, 2.0, 1e-12);
    EXPECT_EQ(J(0, 1), 0.0);  // the dropped entry stays dropped
  }
  // Reached through the wider pattern: the flag comes along.
  JacobianPattern narrow = wrong.pattern();
  narrow.wider = [&pattern] { return pattern; };
  {
    const CorrectorJacobians loose(0.5 * e * 1e-3);
    ASSERT_EQ(compressed_finite_difference_jacobian(wrong, x, narrow, J, {}, &report),
              EvalStatus::ok);
    EXPECT_TRUE(report.widened);
    EXPECT_TRUE(report.kept_unchecked);
    EXPECT_FALSE(report.fell_back);
  }
}

TEST(CompressedJacobian, AWrongPatternIsCaughtAndTheJacobianRecomputedColumnByColumn) {
  // Dropping the superdiagonal leaves cos(x_{i+1}) ~ 0.3..1 out of every row: the check sees
  // errors of |J_ij h_j| ~ 1e-8 against a tolerance of 1e-3 of the row's ~1e-7 size.
  const int n = 20;
  Arrow wrong(n, /*drop_superdiagonal=*/true);
  const Vector x = point(n);
  Matrix J;
  const CompressedJacobianReport report = compress(wrong, x, J);
  EXPECT_TRUE(report.fell_back);
  EXPECT_GT(report.check_error, 1.0);
  Matrix dense;
  ASSERT_EQ(finite_difference_jacobian(wrong, x, dense), EvalStatus::ok);
  EXPECT_EQ((J - dense).cwiseAbs().maxCoeff(), 0.0);
  // Through Problem::jacobian (the default Jacobian uses the declared pattern): counted.
  wrong.reset_counters();
  ASSERT_EQ(wrong.jacobian(x, J), EvalStatus::ok);
  EXPECT_EQ(wrong.counters().compressed_jacobians, 1);
  EXPECT_EQ(wrong.counters().jacobian_fallbacks, 1);
  Arrow right(n);
  ASSERT_EQ(right.jacobian(x, J), EvalStatus::ok);
  EXPECT_EQ(right.counters().compressed_jacobians, 1);
  EXPECT_EQ(right.counters().jacobian_fallbacks, 0);
  EXPECT_EQ(right.counters().residuals, 1 + 4 + 1);
  Arrow undeclared(n, false, /*declare=*/false);
  ASSERT_EQ(undeclared.jacobian(x, J), EvalStatus::ok);
  EXPECT_EQ(undeclared.counters().compressed_jacobians, 0);
  EXPECT_EQ(undeclared.counters().residuals, 1 + n + 1);
}

TEST(CompressedJacobian, AFailedCheckTriesTheWiderPatternBeforeColumnByColumn) {
  const int n = 20;
  Arrow wrong(n, /*drop_superdiagonal=*/true), right(n);
  const Vector x = point(n);
  JacobianPattern pattern = wrong.pattern();
  int built = 0;
  pattern.wider = [&] {
    ++built;
    return right.pattern();
  };
  Matrix J, dense;
  CompressedJacobianReport report;
  ASSERT_EQ(compressed_finite_difference_jacobian(wrong, x, pattern, J, {}, &report),
            EvalStatus::ok);
  EXPECT_TRUE(report.widened);
  EXPECT_FALSE(report.fell_back);
  // Both tries: F(x), colours and check of each (the wrong pattern is bidiagonal: 2 + 1
  // colours; the right one 3 + 1).
  EXPECT_EQ(report.residuals, (1 + 3 + 1) + (1 + 4 + 1));
  ASSERT_EQ(finite_difference_jacobian(wrong, x, dense), EvalStatus::ok);
  EXPECT_EQ((J - dense).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(built, 1);  // built only when the check failed
  // A wider pattern that is wrong too ends column by column.
  pattern.wider = [&] { return wrong.pattern(); };
  ASSERT_EQ(compressed_finite_difference_jacobian(wrong, x, pattern, J, {}, &report),
            EvalStatus::ok);
  EXPECT_TRUE(report.widened);
  EXPECT_TRUE(report.fell_back);
  EXPECT_EQ((J - dense).cwiseAbs().maxCoeff(), 0.0);
}

// F_i = 2 x_i + c x_{i+1}, declared diagonal: the dropped entries are c / 2 of their row's
// diagonal. With the check direction's weights +-(1..2) the check sees them at c / 4 to c of
// the row's first-order size (plus the floor's 1 %), so c = 1e-4 passes the default tolerance
// 1e-3 unnoticed (J without them) and is caught at a pattern's check_tolerance 1e-5 (< c / 4.04);
// the function is linear, so the finite differences' own error is round-off, ~1e-8 of a row.
class WeaklyCoupled : public Problem {
 public:
  int num_unknowns() const override { return 8; }
  int num_equations() const override { return 8; }
  JacobianPattern diagonal() const {
    JacobianPattern p;
    p.row_columns.resize(8);
    for (int i = 0; i < 8; ++i) p.row_columns[static_cast<std::size_t>(i)] = {i};
    return p;
  }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    for (int i = 0; i < 8; ++i) r[i] = 2 * x[i] + (i + 1 < 8 ? 1e-4 * x[i + 1] : 0.0);
    return EvalStatus::ok;
  }
};

TEST(CompressedJacobian, APatternsCheckToleranceBoundsWhatItMayDropUnnoticed) {
  const WeaklyCoupled problem;
  const Vector x = Vector::LinSpaced(8, 0.5, 1.5);
  Matrix J, dense;
  ASSERT_EQ(finite_difference_jacobian(problem, x, dense), EvalStatus::ok);
  JacobianPattern pattern = problem.diagonal();
  CompressedJacobianReport report;
  ASSERT_EQ(compressed_finite_difference_jacobian(problem, x, pattern, J, {}, &report),
            EvalStatus::ok);
  EXPECT_FALSE(report.fell_back);
  EXPECT_EQ(J(0, 1), 0.0);  // dropped, below the default tolerance
  pattern.check_tolerance = 1e-5;
  ASSERT_EQ(compressed_finite_difference_jacobian(problem, x, pattern, J, {}, &report),
            EvalStatus::ok);
  EXPECT_TRUE(report.fell_back);
  EXPECT_EQ((J - dense).cwiseAbs().maxCoeff(), 0.0);
}

TEST(CompressedJacobian, ColouringSeparatesColumnsThatShareARowAndRejectsBadPatterns) {
  Arrow arrow(30);
  const JacobianPattern pattern = arrow.pattern();
  const std::vector<int> colour = colour_columns(pattern, 30, 31);
  for (const auto& row : pattern.row_columns) {
    std::set<int> seen;
    for (int j : row) EXPECT_TRUE(seen.insert(colour[static_cast<std::size_t>(j)]).second);
    EXPECT_EQ(seen.count(colour[30]), 0u);  // the dense column shares no colour
  }
  JacobianPattern short_pattern = pattern;
  short_pattern.row_columns.pop_back();
  EXPECT_THROW(colour_columns(short_pattern, 30, 31), InputError);
  JacobianPattern out_of_range = pattern;
  out_of_range.row_columns[3].push_back(31);
  EXPECT_THROW(colour_columns(out_of_range, 30, 31), InputError);
}

}  // namespace
