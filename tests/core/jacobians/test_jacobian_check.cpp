// Finite-difference Jacobians against a known analytic Jacobian, and the Jacobian checker
// catching a wrong entry.
#include <gtest/gtest.h>

#include <cmath>

#include "core/jacobians/finite_difference.hpp"
#include "core/jacobians/jacobian_check.hpp"

namespace backbone::core {
namespace {

// F = (sin(x0) x1, exp(x0) + x1^3, x0^2 x1^2) with its exact Jacobian; `bug` corrupts one
// entry so the checker has something to find.
class Smooth : public Problem {
 public:
  explicit Smooth(bool bug = false) : bug_(bug) {}
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 3; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r << std::sin(x[0]) * x[1], std::exp(x[0]) + x[1] * x[1] * x[1], x[0] * x[0] * x[1] * x[1];
    return EvalStatus::ok;
  }
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override {
    J << std::cos(x[0]) * x[1], std::sin(x[0]),  //
        std::exp(x[0]), 3 * x[1] * x[1],         //
        2 * x[0] * x[1] * x[1], 2 * x[0] * x[0] * x[1];
    if (bug_) J(2, 1) *= 1.001;  // a 0.1% slip, e.g. a dropped factor in a long expression
    return EvalStatus::ok;
  }

 private:
  bool bug_;
};

Vector point() {
  Vector x(2);
  x << 0.7, 1.3;
  return x;
}

TEST(FiniteDifference, ForwardAndCentralMatchTheAnalyticJacobian) {
  Smooth p;
  Matrix exact, forward, central;
  ASSERT_EQ(p.jacobian(point(), exact), EvalStatus::ok);
  FiniteDifferenceOptions fd;
  ASSERT_EQ(finite_difference_jacobian(p, point(), forward, fd), EvalStatus::ok);
  fd.scheme = FiniteDifferenceOptions::Scheme::central;
  fd.threads = 2;  // columns in parallel: same numbers
  ASSERT_EQ(finite_difference_jacobian(p, point(), central, fd), EvalStatus::ok);
  // Step rule: h = 1.5e-8 * max(|x_j|, 1) = 1.5e-8 (forward), 6.1e-6 (central). Here |F|,
  // |F''| and |F'''| are all <= ~15, so forward error <= h/2 |F''| + 2 eps |F| / h ~ 1.5e-7
  // and central error <= h^2/6 |F'''| + eps |F| / h ~ 1e-10 + 5e-10. Bounds with a 3x margin:
  EXPECT_LT((forward - exact).cwiseAbs().maxCoeff(), 5e-7);
  EXPECT_LT((central - exact).cwiseAbs().maxCoeff(), 2e-9);
  // And central must really be the better scheme here (otherwise the test above is too loose
  // to tell the schemes apart).
  EXPECT_LT((central - exact).cwiseAbs().maxCoeff(), 0.1 * (forward - exact).cwiseAbs().maxCoeff());
}

TEST(JacobianCheck, CorrectJacobianPasses) {
  const JacobianCheck c = check_jacobian(Smooth(), point());
  ASSERT_EQ(c.status, EvalStatus::ok);
  // Same bounds as above, divided by the smallest column norm (~1.6): relative.
  EXPECT_LT(c.forward.max_relative_error, 5e-7);
  EXPECT_LT(c.central.max_relative_error, 2e-9);
  EXPECT_EQ(c.central.column_relative_error.size(), 2);
}

TEST(JacobianCheck, FindsTheWrongEntry) {
  const JacobianCheck c = check_jacobian(Smooth(true), point());
  ASSERT_EQ(c.status, EvalStatus::ok);
  // J(2, 1) = 2 x0^2 x1 = 1.274 off by 0.1%: absolute error 1.3e-3, far above FD noise.
  EXPECT_EQ(c.central.worst_row, 2);
  EXPECT_EQ(c.central.worst_column, 1);
  EXPECT_NEAR(c.central.max_absolute_error, 1.274e-3, 1e-5);
  EXPECT_GT(c.central.column_relative_error[1], 1e-4);
  EXPECT_LT(c.central.column_relative_error[0], 2e-9);
  EXPECT_NE(c.summary().find("(2, 1)"), std::string::npos) << c.summary();
}

}  // namespace
}  // namespace backbone::core
