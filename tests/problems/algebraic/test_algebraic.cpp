// Dimensions of known solution sets by the verified rank report.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/newton.hpp"
#include "problems/algebraic/algebraic.hpp"

using namespace backbone;

namespace {
core::RankReport verified_report(const core::Problem& p, const core::Vector& x) {
  core::Matrix J;
  EXPECT_EQ(p.jacobian(x, J), core::EvalStatus::ok);
  core::RankReport r = core::rank_report(J, core::RankOptions{});
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  core::verify_null_directions(p, x, *newton, core::VerifyOptions{}, r);
  return r;
}
}  // namespace

TEST(Algebraic, SphereHasDimensionTwo) {
  algebraic::Sphere sphere;
  core::Vector x(3);
  x << 0.6, 0.0, 0.8;
  const core::RankReport r = verified_report(sphere, x);
  EXPECT_EQ(r.nullity, 2);
  EXPECT_EQ(r.verified_dimension, 2);
}

TEST(Algebraic, CircleAndFoldCurveHaveDimensionOne) {
  algebraic::Circle circle(2.0);
  core::Vector c(2);
  c << 0.0, 2.0;
  EXPECT_EQ(verified_report(circle, c).verified_dimension, 1);
  algebraic::FoldCurve fold;
  for (double s : {-1.0, 0.0, 0.5}) {  // 0.0: the fold itself, J = [0, 1] still has rank 1
    core::Vector x(2);
    x << s, 1.0 - s * s;
    const core::RankReport r = verified_report(fold, x);
    EXPECT_EQ(r.nullity, 1) << "x = " << s;
    EXPECT_EQ(r.verified_dimension, 1) << "x = " << s;
  }
}

TEST(Algebraic, BadRadiusIsInputError) {
  EXPECT_THROW(algebraic::Circle(-1.0), core::InputError);
}
