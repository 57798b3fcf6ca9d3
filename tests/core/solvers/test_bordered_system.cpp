// The bordered system F plus k rows on algebraic sets whose constrained points are known in
// closed form: the circle (k = 1 gives a point) and the 2-sphere (k = 2 gives an isolated point,
// with linear rows, an observable row, or both), its Jacobian rows against finite differences
// and closed-form gradients, mutable rows reused in a loop, and configuration errors.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "core/errors.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/bordered_system.hpp"
#include "core/solvers/newton.hpp"
#include "problems/algebraic/algebraic.hpp"

namespace backbone::core {
namespace {

Vector vec(std::initializer_list<double> values) {
  Vector v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double value : values) v[i++] = value;
  return v;
}

NewtonOptions tight() {
  NewtonOptions o;
  o.residual_tolerance = 1e-13;
  return o;
}

// Newton's last residual is <= 1e-13 on rows of order one with gradients of order one, so each
// coordinate of the solution is within a few 1e-13 of the exact point: 1e-12 leaves a margin.
constexpr double point_tolerance = 1e-12;

class BothBackends : public ::testing::TestWithParam<const char*> {};

// k = 1 on the circle of radius 2: x fixed at 1.2 leaves the single point (1.2, 1.6) near the
// guess (the other intersection is (1.2, -1.6)).
TEST_P(BothBackends, OneRowOnTheCircleIsAPoint) {
  const algebraic::Circle circle(2.0);
  const BorderedSystem fixed_x(circle, {BorderRow::fixed_unknown(2, 0, 1.2, "x fixed")});
  EXPECT_EQ(fixed_x.num_equations(), 2);
  EXPECT_EQ(fixed_x.num_unknowns(), 2);
  auto newton = make_corrector(GetParam(), tight());
  Vector x = vec({1.0, 1.0});
  const NewtonSummary s = newton->solve(fixed_x, x);
  ASSERT_TRUE(s.converged()) << s.message;
  EXPECT_NEAR(x[0], 1.2, point_tolerance);
  EXPECT_NEAR(x[1], 1.6, point_tolerance);
}

// k = 2 on the unit 2-sphere, both rows tangent-space hyperplanes of the chart at the north pole
// (normals e_x, e_y) moved through the anchor (a, b, 1): the isolated point (a, b,
// sqrt(1 - a^2 - b^2)). One system, its anchors moved in a loop, as an atlas would use it.
TEST_P(BothBackends, TwoRowsOnTheSphereGiveAnIsolatedPointAndMoveInALoop) {
  const algebraic::Sphere sphere;
  const Vector pole = vec({0, 0, 1});
  BorderedSystem chart(sphere, {BorderRow::hyperplane(Vector::Unit(3, 0), pole),
                                BorderRow::hyperplane(Vector::Unit(3, 1), pole)});
  EXPECT_EQ(chart.num_equations(), 3);
  auto newton = make_corrector(GetParam(), tight());
  const std::pair<double, double> anchors[] = {{0.3, 0.2}, {-0.5, 0.1}, {0.6, -0.6}};
  for (const auto& [a, b] : anchors) {
    const Vector anchor = vec({a, b, 1.0});
    chart.set_anchor(0, anchor);
    chart.set_anchor(1, anchor);
    Vector x = anchor;
    const NewtonSummary s = newton->solve(chart, x);
    ASSERT_TRUE(s.converged()) << a << " " << b << ": " << s.message;
    EXPECT_NEAR(x[0], a, point_tolerance);
    EXPECT_NEAR(x[1], b, point_tolerance);
    EXPECT_NEAR(x[2], std::sqrt(1 - a * a - b * b), point_tolerance);
    // Isolated: the bordered Jacobian has full rank 3 (nullity 0).
    Matrix J;
    ASSERT_EQ(chart.jacobian(x, J), EvalStatus::ok);
    EXPECT_EQ(rank_report(J, RankOptions{}).nullity, 0);
  }
}

// k = 2 with an observable row, the shape of "F + energy row + tangent rows": z fixed at 0.6
// (observable row) and the plane x + y = 0 leave (0.4 sqrt 2, -0.4 sqrt 2, 0.6) near the guess.
// set_value then moves the observable row to z = 0.8: (0.3 sqrt 2, -0.3 sqrt 2, 0.8).
TEST_P(BothBackends, ObservableAndLinearRowOnTheSphere) {
  const algebraic::Sphere sphere;
  BorderedSystem system(sphere, {BorderRow::observable("z", 0.6),
                                 BorderRow::hyperplane(vec({1, 1, 0}), Vector::Zero(3))});
  EXPECT_EQ(system.name(), "sphere + z fixed + hyperplane");
  auto newton = make_corrector(GetParam(), tight());
  for (const double z : {0.6, 0.8}) {
    system.set_value(0, z);
    Vector x = vec({0.5, -0.5, 0.5});
    const NewtonSummary s = newton->solve(system, x);
    ASSERT_TRUE(s.converged()) << z << ": " << s.message;
    const double xy = std::sqrt((1 - z * z) / 2);
    // The observable row is divided by |z| (< 1): the tolerance above still holds.
    EXPECT_NEAR(x[0], xy, point_tolerance) << z;
    EXPECT_NEAR(x[1], -xy, point_tolerance) << z;
    EXPECT_NEAR(x[2], z, point_tolerance) << z;
  }
}

INSTANTIATE_TEST_SUITE_P(BorderedSystem, BothBackends, ::testing::Values("eigen", "kinsol"));

// The analytic Jacobian (base rows analytic, linear rows exact, observable rows by central
// differences) against central differences of the whole bordered residual at a point off the
// sphere. Every row is a polynomial of degree <= 2 except the angle's, so central differences
// are exact up to round-off eps * |r| / h ~ 1e-16 / 6e-6 ~ 2e-11 (the angle's truncation
// h^2 f''' ~ 4e-11 on top): 1e-8 is safe and far below the rows' size.
TEST(BorderedSystem, JacobianRowsMatchFiniteDifferences) {
  const algebraic::Sphere sphere(1.5);
  const Vector x = vec({0.7, -0.4, 1.1});
  BorderedSystem system(
      sphere, {BorderRow::linear(vec({0.3, -2.0, 0.5}), vec({1, 2, 3}), 0.25, "arclength"),
               BorderRow::observable("angle", -0.8), BorderRow::observable("z", 0.0)});
  Matrix analytic, numeric;
  ASSERT_EQ(system.jacobian(x, analytic), EvalStatus::ok);
  FiniteDifferenceOptions central;
  central.scheme = FiniteDifferenceOptions::Scheme::central;
  ASSERT_EQ(finite_difference_jacobian(system, x, numeric, central), EvalStatus::ok);
  ASSERT_EQ(analytic.rows(), 4);
  EXPECT_LT((analytic - numeric).lpNorm<Eigen::Infinity>(), 1e-8) << analytic << "\n" << numeric;
  // Independent oracles: the linear row is its direction; the angle atan2(y, x) has gradient
  // (-y, x, 0) / (x^2 + y^2), divided by the row scale |-0.8|; the z row (value 0, scale 1) is
  // e_z.
  EXPECT_EQ(analytic.row(1), vec({0.3, -2.0, 0.5}).transpose());
  const double rho2 = x[0] * x[0] + x[1] * x[1];
  const Vector angle_gradient = vec({-x[1] / rho2, x[0] / rho2, 0.0}) / 0.8;
  EXPECT_LT((analytic.row(2).transpose() - angle_gradient).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LT((analytic.row(3).transpose() - Vector::Unit(3, 2)).lpNorm<Eigen::Infinity>(), 1e-9);
}

// The rows' values: a . (x - anchor) - value, and (obs - value) / |value| with the divisor 1 at
// value 0 (exact arithmetic on these small numbers up to one rounding).
TEST(BorderedSystem, RowsAndTheirScaling) {
  const algebraic::Sphere sphere;
  const Vector x = vec({0.5, 0.25, 2.0});
  BorderedSystem system(sphere,
                        {BorderRow::linear(vec({1, 2, 0}), vec({0.5, 0, 0}), 0.125, "l"),
                         BorderRow::observable("z", -4.0), BorderRow::observable("x", 0.0)});
  Vector r;
  ASSERT_EQ(system.residual(x, r), EvalStatus::ok);
  ASSERT_EQ(r.size(), 4);
  EXPECT_DOUBLE_EQ(r[0], 0.25 + 0.0625 + 4.0 - 1.0);  // the sphere's residual
  EXPECT_DOUBLE_EQ(r[1], 2 * 0.25 - 0.125);
  EXPECT_DOUBLE_EQ(r[2], (2.0 + 4.0) / 4.0);
  EXPECT_DOUBLE_EQ(r[3], 0.5);
  EXPECT_EQ(system.row_scale(0), 1.0);
  EXPECT_EQ(system.row_scale(1), 4.0);
  EXPECT_EQ(system.row_scale(2), 1.0);
  // Observables and typical scale are the base's.
  EXPECT_EQ(system.observables(x).size(), sphere.observables(x).size());
  EXPECT_EQ(system.typical_scale(), sphere.typical_scale());
}

TEST(BorderedSystem, AnObservableTheBaseDoesNotReportFailsTheEvaluation) {
  const algebraic::Sphere sphere;
  const BorderedSystem system(sphere, {BorderRow::observable("energy", 1.0)});
  Vector r;
  EXPECT_EQ(system.residual(vec({1, 0, 0}), r), EvalStatus::failed);
}

TEST(BorderedSystem, BadRowsAreInputErrorsNamingTheSystem) {
  const algebraic::Sphere sphere;
  const auto expect_error = [](auto&& make) {
    try {
      make();
      ADD_FAILURE() << "no exception";
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), "bordered_system");
    }
  };
  expect_error([&] { BorderedSystem s(sphere, {}); });
  expect_error([&] {
    BorderedSystem s(sphere, {BorderRow::hyperplane(vec({1, 0}), vec({0, 0}))});
  });
  expect_error([&] { BorderRow::fixed_unknown(3, 3, 0.0, "w"); });
  expect_error([&] { BorderedSystem s(sphere, {BorderRow::observable("", 1.0)}); });
  BorderedSystem s(sphere, {BorderRow::observable("z", 1.0)});
  expect_error([&] { s.set_anchor(0, Vector::Zero(3)); });  // not a linear row
  expect_error([&] { s.set_value(1, 0.0); });               // out of range
  BorderedSystem t(sphere, {BorderRow::hyperplane(Vector::Unit(3, 0), Vector::Zero(3))});
  expect_error([&] { t.set_direction(0, Vector::Zero(2)); });
  expect_error([&] { t.set_anchor(0, vec({0, std::nan(""), 0})); });
}

}  // namespace
}  // namespace backbone::core
