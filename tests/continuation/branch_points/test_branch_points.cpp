// Branch points along pseudo-arclength branches of algebraic curves whose branch points are known
// exactly (problems/algebraic/algebraic.hpp): detection, location, verification (dimension of
// the attached family, angle between the branches) and passing through on the traced curve.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <numbers>
#include <utility>

#include "continuation/branch_points/branch_points.hpp"
#include "continuation/branch_points/follow.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "problems/algebraic/algebraic.hpp"
#include "tests/continuation/test_support.hpp"

using namespace backbone;
using continuation::Branch;
using continuation_tests::detecting;
using continuation_tests::vec;

namespace {

double largest_abs(const Branch& b, int coordinate) {
  double worst = 0;
  for (const auto& p : b.points) worst = std::max(worst, std::abs(p.x[coordinate]));
  return worst;
}

// The transcritical in units that grow along the branch (continuation::LocalScale): lambda and
// the equation in units of 1 + lambda^2, x in fixed units. With them a step ds covers
// (1 + lambda^2) ds of lambda, and J in the point's units has its lambda column multiplied and its
// row divided by that factor.
class TranscriticalInGrowingUnits : public algebraic::Transcritical,
                                    public continuation::LocalScale {
 public:
  explicit TranscriticalInGrowingUnits(bool enabled) : enabled_(enabled) {}
  bool local_scale_enabled() const override { return enabled_; }
  core::Vector local_scale_factor(const core::Vector& x) const override {
    return vec({1, 1 + x[1] * x[1]});
  }
  core::Vector local_residual_factor(const core::Vector& x) const override {
    return vec({1 + x[1] * x[1]});
  }

 private:
  bool enabled_;
};

// J (m x n) and t such that [J; t^T / |t|] = (U diag(sigma) V^T) / |t| for random orthonormal U
// (m + 1 x n) and V (seeded): bordered_test_function normalises t, so the whole matrix is
// scaled by the bordered row's norm t_norm, and its singular values are sigma / t_norm.
struct BorderedParts {
  core::Matrix J;
  core::Vector t;
  double t_norm;
};
BorderedParts bordered_with_singular_values(Eigen::Index m, const core::Vector& sigma,
                                            unsigned seed) {
  const Eigen::Index n = sigma.size();
  std::srand(seed);
  const core::Matrix U =
      Eigen::HouseholderQR<core::Matrix>(core::Matrix::Random(m + 1, n)).householderQ() *
      core::Matrix::Identity(m + 1, n);
  const core::Matrix V =
      Eigen::HouseholderQR<core::Matrix>(core::Matrix::Random(n, n)).householderQ();
  const core::Matrix bordered = U * sigma.asDiagonal() * V.transpose();
  const double t_norm = bordered.row(m).norm();
  return {bordered.topRows(m) / t_norm, bordered.row(m).transpose() / t_norm, t_norm};
}

}  // namespace

// The detector keeps its samples in the unit scale: a point added in other units (the loop's,
// when they follow the point) gives the same test-function value and the same stored point as in
// fixed units. Here the second point's J in its units is [(lambda - 1) / 2, 0]: a value computed
// from it directly would be half the fixed units' (the first point fixes the Jacobian scale).
TEST(BranchPointDetector, SamplesDoNotDependOnTheLoopsUnits) {
  const TranscriticalInGrowingUnits problem(true);
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const continuation::ContinuationOptions options = detecting(0.1, 10);
  const continuation::ContinuationHooks hooks;
  const core::Vector t = vec({0, 1});
  const core::Vector first = vec({0, 0.25}), second = vec({0, 0.5});
  const auto add_both = [&](const core::Vector& factor, const core::Vector& residual_factor) {
    continuation::ScaledProblem scaled(problem);
    continuation::BranchPointDetector detector(scaled, options, hooks, *newton);
    core::Matrix J;
    scaled.jacobian(first, J);
    detector.add(0, first, t, J, 0.0);
    scaled.set_factor(factor, residual_factor);
    const core::Vector z = scaled.to_scaled(second);
    scaled.jacobian(z, J);
    detector.add(1, z, t.cwiseQuotient(factor).normalized(), J, 0.25);
    return std::make_pair(detector.last_value(), core::Vector(detector.samples().back().z));
  };
  const auto [fixed_value, fixed_z] = add_both(vec({1, 1}), core::Vector());
  const auto [local_value, local_z] = add_both(vec({1, 1.25}), vec({2}));
  EXPECT_NEAR(std::abs(fixed_value), 0.5 / 0.75, 1e-14);  // |lambda - 1| / |J_0|_F
  EXPECT_NEAR(local_value, fixed_value, 1e-14);
  EXPECT_LE((local_z - fixed_z).norm(), 1e-15);
  EXPECT_LE((fixed_z - second).norm(), 1e-15);
}

// Detection along a branch whose units follow the point: the branch point at lambda = 1 is found,
// located and verified as in fixed units, while the steps (ds in the point's units) cover more of
// lambda (the units were followed).
TEST(BranchPoints, LocatedInUnitsThatFollowThePoint) {
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  double last_lambda[2] = {0, 0};
  for (bool follow : {false, true}) {
    const TranscriticalInGrowingUnits problem(follow);
    const Branch b = continuation::pseudo_arclength(problem, vec({0, 0}), vec({0, 1}), *newton,
                                                    detecting(0.13, 10));
    ASSERT_EQ(b.points.size(), 10u) << b.message;
    EXPECT_LE(largest_abs(b, 0), 1e-12);
    ASSERT_EQ(b.branch_points.size(), 1u) << follow;
    const auto& r = b.branch_points[0];
    EXPECT_NEAR(r.x[1], 1.0, 1e-9);  // the secant on a test function linear in lambda
    EXPECT_EQ(r.attached_dimension, 1);
    EXPECT_NEAR(r.tangent_angle, 45.0, 1e-3);  // as in TranscriticalLocatedVerifiedAndPassed
    last_lambda[follow] = b.points.back().x[1];
  }
  EXPECT_NEAR(last_lambda[0], 9 * 0.13, 1e-12);
  EXPECT_GT(last_lambda[1], 1.5 * last_lambda[0]);  // steps of (1 + lambda^2) ds
}

// With a clone() the candidates are located on a second thread (BranchPointOptions::background),
// in a copy of the problem set to the loop's units of the moment each was bracketed: the reports
// and the branch must be the bits the loop's own thread gives, in units that follow the point and
// with two candidates queued (the axis meets the circle twice, algebraic.hpp). These small
// problems run the worker under the sanitizers (.ci/sanitize); the contact bar's CLI test
// (SecondThreadGivesTheRowsOfTheLoopsOwnBitForBit) is the one whose rows move when the worker
// misses the loop's units (measured: 42 differing values; here the two-unknown problems give the
// same bits in either units).
template <class P>
class Cloned : public P {
 public:
  using P::P;
  std::unique_ptr<core::Problem> clone() const override { return std::make_unique<Cloned>(*this); }
};

// The branch with detection on the loop's thread and on the worker's: the same bits.
void expect_same_on_both_threads(const core::Problem& problem, const core::Vector& start,
                                 continuation::ContinuationOptions o, std::size_t candidates) {
  ASSERT_NE(problem.clone(), nullptr);
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  Branch runs[2];
  for (bool background : {false, true}) {
    o.branch_points.background = background;
    runs[background] = continuation::pseudo_arclength(problem, start, vec({0, 1}), *newton, o);
  }
  ASSERT_EQ(runs[0].branch_points.size(), candidates);
  ASSERT_EQ(runs[1].branch_points.size(), candidates);
  for (std::size_t i = 0; i < candidates; ++i) {
    const auto& a = runs[0].branch_points[i];
    const auto& b = runs[1].branch_points[i];
    EXPECT_TRUE(a.x == b.x) << i;
    EXPECT_EQ(a.attached_dimension, b.attached_dimension) << i;
    EXPECT_EQ(a.tangent_angle, b.tangent_angle) << i;
    EXPECT_EQ(a.after_point, b.after_point) << i;
    EXPECT_EQ(a.jacobian_evaluations, b.jacobian_evaluations) << i;
    EXPECT_EQ(a.residual_evaluations, b.residual_evaluations) << i;
  }
  ASSERT_EQ(runs[0].points.size(), runs[1].points.size());
  for (std::size_t i = 0; i < runs[0].points.size(); ++i) {
    EXPECT_TRUE(runs[0].points[i].x == runs[1].points[i].x) << i;
    EXPECT_EQ(runs[0].points[i].residual_evaluations, runs[1].points[i].residual_evaluations) << i;
  }
}

TEST(BranchPoints, SecondThreadGivesTheLoopsOwnReports) {
  expect_same_on_both_threads(Cloned<TranscriticalInGrowingUnits>(true), vec({0, 0}),
                              detecting(0.13, 10), 1);
  expect_same_on_both_threads(Cloned<algebraic::AxisAndCircle>(), vec({0, -1.6}),
                              detecting(0.15, 24), 2);
}

// [J/s; t^T] of the transcritical on x = 0 is diag((lambda - 1)/s, 1): the signed test function
// is (lambda - 1)/s, up to an orientation fixed by the first point.
TEST(BorderedTestFunction, ChangesSignAcrossASimpleBranchPoint) {
  const algebraic::Transcritical problem;
  core::Matrix J;
  const core::Vector t = vec({0, 1});
  problem.jacobian(vec({0, 0.5}), J);
  const auto before = continuation::bordered_test_function(J, t, 1.0, nullptr);
  problem.jacobian(vec({0, 1.25}), J);
  const auto after = continuation::bordered_test_function(J, t, 1.0, &before);
  EXPECT_NEAR(std::abs(before.value), 0.5, 1e-14);
  EXPECT_NEAR(after.value, -before.value * 0.5, 1e-14);  // |0.25| with the opposite sign
  EXPECT_TRUE(after.continued);
}

// The test function comes from a Krylov basis of inverse iteration on a QR factor (iterate =
// true; the SVD when it does not converge); the SVD is the oracle. Matrices [J; t^T] of 41 x 20
// with chosen singular values: a regular point (smallest 1e-2, gap 10), one at a located branch
// point (1e-9) and a cluster (1e-6 and 1.000001e-6, where the iteration falls back to the SVD or
// converges to the same value). Both are backward stable, so the values agree to a few
// round-offs of |A| ~ 1 (1e-13 allows ~500 eps); the right vectors, where the gap separates
// them (>= 1e-2), to round-off over the gap (1 - |v . v'| <= 1e-10).
TEST(BorderedTestFunction, InverseIterationAgreesWithTheSvd) {
  const Eigen::Index n = 20;
  for (const auto& [smallest, second] :
       {std::pair{1e-2, 1e-1}, std::pair{1e-9, 1e-1}, std::pair{1e-6, 1.000001e-6}}) {
    core::Vector sigma = core::Vector::LinSpaced(n, 1.0, 0.2);
    sigma[n - 2] = second;
    sigma[n - 1] = smallest;
    const auto [J, t, t_norm] = bordered_with_singular_values(40, sigma, 7);
    const auto svd = continuation::bordered_test_function(J, t, 0.0, nullptr, false);
    const auto iterated = continuation::bordered_test_function(J, t, 0.0, nullptr, true);
    EXPECT_NEAR(iterated.value, svd.value, 1e-13) << smallest;
    EXPECT_NEAR(svd.value, smallest / t_norm, 1e-13) << smallest;
    if (second / smallest >= 10) {
      EXPECT_LE(1 - std::abs(iterated.right.dot(svd.right)), 1e-10) << smallest;
      EXPECT_LE(1 - std::abs(iterated.left.dot(svd.left)), 1e-10) << smallest;
    }
    // From a reference (the previous point's triplet), signed and oriented alike.
    const auto svd_ref = continuation::bordered_test_function(J, t, 0.0, &svd, false);
    const auto iterated_ref = continuation::bordered_test_function(J, t, 0.0, &svd, true);
    EXPECT_NEAR(iterated_ref.value, svd_ref.value, 1e-13) << smallest;
  }
}

// Near a branch point of the contact bar some twenty singular values of [J; t^T] vanish together;
// the Krylov basis of inverse iteration resolves the smallest of such a cluster (here 19 values
// spread geometrically over 1e-9..1e-7, the rest 0.2..1) where one vector converges as
// (1e-9 / 1.3e-9)^2 per step. The SVD is the oracle: the Ritz value lies within its residual,
// accepted at 1e-4 of the value (plus 1e-12 |A|_F, |A|_F ~ 3), of a singular value, and it is
// the smallest one when it is below the second (1.29e-9).
TEST(BorderedTestFunction, KrylovResolvesTheSmallestOfACluster) {
  const Eigen::Index n = 30;
  core::Vector sigma = core::Vector::LinSpaced(n, 1.0, 0.2);
  for (Eigen::Index i = 0; i < 19; ++i) sigma[n - 1 - i] = 1e-9 * std::pow(100.0, i / 18.0);
  const auto [J, t, t_norm] = bordered_with_singular_values(60, sigma, 11);
  const auto svd = continuation::bordered_test_function(J, t, 0.0, nullptr, false);
  const auto krylov = continuation::bordered_test_function(J, t, 0.0, nullptr, true);
  EXPECT_NEAR(svd.value, 1e-9 / t_norm, 1e-15);
  EXPECT_NEAR(krylov.value, svd.value, 1e-4 * svd.value + 1e-12 * 3);
}

// The line x = 0 traced upwards in lambda crosses x = lambda - 1 at (0, 1): one candidate,
// located to the location tolerance (the test function is linear in lambda, so the secant
// iteration is exact up to round-off), with a one-dimensional attached family at 45 degrees,
// and the branch stays on x = 0 (exactly: the corrector never leaves it).
TEST(BranchPoints, TranscriticalLocatedVerifiedAndPassed) {
  for (int copies : {1, 3}) {  // 3: consistent overdetermined, least-squares corrector
    const algebraic::Transcritical problem(copies);
    auto newton = core::make_corrector("eigen", core::NewtonOptions{});
    const Branch b = continuation::pseudo_arclength(problem, vec({0, 0}), vec({0, 1}), *newton,
                                                    detecting(0.13, 20));
    ASSERT_EQ(b.points.size(), 20u) << b.message;
    EXPECT_LE(largest_abs(b, 0), 1e-12);
    ASSERT_EQ(b.branch_points.size(), 1u);
    const auto& r = b.branch_points[0];
    EXPECT_TRUE(r.sign_change);
    EXPECT_NEAR(r.x[1], 1.0, 1e-9);
    EXPECT_NEAR(r.x[0], 0.0, 1e-12);
    EXPECT_EQ(r.after_point, 7);  // lambda = 0.91 at point 7, 1.04 at point 8
    EXPECT_EQ(r.attached_dimension, 1);
    // Probe at h = 1e-3 from a point within 1e-9 of the exact one: the secant's angle is off by
    // about 1e-9 / 1e-3 rad = 6e-5 degrees.
    EXPECT_NEAR(r.tangent_angle, 45.0, 1e-3);
    EXPECT_NEAR(r.attached_point[1] - 1.0, r.attached_point[0], 1e-9);  // on x = lambda - 1
  }
}

// The y axis meets the unit circle at y = -1 and y = 1: two candidates at right angles (the
// probe's secant to the circle x^2 + y^2 = 1 from (0, 1) at x = h tilts by h/2 rad).
TEST(BranchPoints, AxisMeetsTheCircleTwice) {
  const algebraic::AxisAndCircle problem;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const Branch b = continuation::pseudo_arclength(problem, vec({0, -1.6}), vec({0, 1}), *newton,
                                                  detecting(0.15, 24));
  ASSERT_EQ(b.points.size(), 24u) << b.message;
  EXPECT_LE(largest_abs(b, 0), 1e-12);
  ASSERT_EQ(b.branch_points.size(), 2u);
  EXPECT_NEAR(b.branch_points[0].x[1], -1.0, 1e-9);
  EXPECT_NEAR(b.branch_points[1].x[1], 1.0, 1e-9);
  for (const auto& r : b.branch_points) {
    EXPECT_EQ(r.attached_dimension, 1);
    EXPECT_NEAR(r.tangent_angle, 90.0, 0.05);  // h/2 rad = 0.03 degrees
  }
}

// The z axis pierces the plane z = 1: the attached family is two-dimensional. The branch passes
// it and stays on the axis.
TEST(BranchPoints, AttachedPlaneHasDimensionTwo) {
  const algebraic::AxisAndPlane problem(2);
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const Branch b = continuation::pseudo_arclength(problem, vec({0, 0, 0.1}), vec({0, 0, 1}),
                                                  *newton, detecting(0.17, 12));
  ASSERT_EQ(b.points.size(), 12u) << b.message;
  EXPECT_LE(std::max(largest_abs(b, 0), largest_abs(b, 1)), 1e-12);
  EXPECT_GT(b.points.back().x[2], 1.5);
  ASSERT_EQ(b.branch_points.size(), 1u);
  EXPECT_NEAR(b.branch_points[0].x[2], 1.0, 1e-9);
  EXPECT_EQ(b.branch_points[0].attached_dimension, 2);
  EXPECT_NEAR(b.branch_points[0].tangent_angle, 90.0, 1e-6);
}

// Without detection nothing is reported, and a regular curve (the circle) has no candidate.
TEST(BranchPoints, NoneOnARegularCurveOrWhenOff) {
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const algebraic::Circle circle;
  const Branch regular =
      continuation::pseudo_arclength(circle, vec({1, 0}), vec({0, 1}), *newton, detecting(0.2, 40));
  EXPECT_TRUE(regular.branch_points.empty());
  const algebraic::Transcritical problem;
  auto options = detecting(0.13, 20);
  options.branch_points.detect = false;
  const Branch off =
      continuation::pseudo_arclength(problem, vec({0, 0}), vec({0, 1}), *newton, options);
  EXPECT_TRUE(off.branch_points.empty());
}

// The turn check refuses a correction that leaves the predictor direction by more than
// max_turn_degrees: on the unit circle from (1, 0) with ds = 1 the arclength row lands on (0, 1),
// a chord 45 degrees from the tangent: refused and retried at ds = 0.5 (15 degrees).
TEST(BranchPoints, TurnCheckShrinksSteepSteps) {
  const algebraic::Circle circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  continuation::ContinuationOptions o;
  o.ds = 1.0;
  o.ds_max = 1.0;
  o.max_points = 3;
  o.rank_check_every = 0;
  const Branch b = continuation::pseudo_arclength(circle, vec({1, 0}), vec({0, 1}), *newton, o);
  ASSERT_EQ(b.points.size(), 3u);
  EXPECT_DOUBLE_EQ(b.points[1].step_size, 0.5);
  o.branch_points.max_turn_degrees = 0;  // off
  const Branch unchecked =
      continuation::pseudo_arclength(circle, vec({1, 0}), vec({0, 1}), *newton, o);
  EXPECT_DOUBLE_EQ(unchecked.points[1].step_size, 1.0);
  o.branch_points.max_turn_degrees = 180;
  EXPECT_THROW(o.validate(), core::InputError);
  // The probes' step must be positive and finite (it scales every probe of a located point).
  o.branch_points.max_turn_degrees = 20;
  for (const double step : {0.0, -1e-3, std::numeric_limits<double>::infinity()}) {
    o.branch_points.probe_step = step;
    EXPECT_THROW(o.validate(), core::InputError) << step;
  }
}

namespace {

// x (lambda - 1 - g(x)) = 0: the line x = 0 and, attached at (0, 1), the polyline lambda = 1 + g(x)
// with a corner at x = c: g(x) = x up to c (45 degrees), then slope tan 15 degrees, a turn of
// 30 degrees. The analytic Jacobian at the corner is the incoming piece's, as a forward-
// difference Jacobian that straddles an edge of a piecewise-affine family is neither piece's (the
// contact bar's attached families at 100 intervals, continuation/branch_points/follow.hpp): the
// tangent there points along the incoming piece, and every step from the corner turns by 30
// degrees, whatever ds is.
class CorneredAttachedLine : public core::Problem {
 public:
  static constexpr double corner = 0.5;
  static double g(double x) { return x <= corner ? x : corner + slope * (x - corner); }
  static inline const double slope = std::tan(15.0 * std::numbers::pi / 180);
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  std::string name() const override { return "cornered_attached_line"; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"x", x[0]}, {"lambda", x[1]}};
  }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(1);
    r[0] = x[0] * (x[1] - 1 - g(x[0]));
    return core::EvalStatus::ok;
  }
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override {
    J.resize(1, 2);
    J(0, 0) = x[1] - 1 - g(x[0]) - x[0] * (x[0] <= corner ? 1.0 : slope);
    J(0, 1) = x[0];
    return core::EvalStatus::ok;
  }
};

}  // namespace

// A followed branch turns the corners of its family: started at the corner of
// CorneredAttachedLine (a probe point there, attached to (0, 1)), the 30-degree turn exceeds the
// traced branch's max_turn_degrees (20), which would refuse every step down to ds_min; the
// followed branch's turn check (follow_max_turn_degrees) lets it through, and every point lies on
// the polyline up to the bound x <= 2 (Newton stops at |x (lambda - 1 - g)| <= 1e-10, so
// |lambda - 1 - g(x)| <= 1e-10 / x, with x >= c).
TEST(BranchPoints, FollowedBranchTurnsACornerOfItsFamily) {
  const CorneredAttachedLine problem;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  continuation::BranchPointReport report;
  report.x = vec({0, 1});
  const double c = CorneredAttachedLine::corner;
  report.attached_points = {vec({c, 1 + c})};
  report.attached_point = report.attached_points[0];
  report.attached_dimension = 1;
  report.verified_dimension = 2;
  continuation::ContinuationOptions options;
  options.ds = options.ds_max = 0.1;
  options.max_points = 60;
  options.rank_check_every = 0;
  options.bounds.push_back({"x", -1.0, 2.0});
  ASSERT_EQ(options.branch_points.max_turn_degrees, 20);
  ASSERT_GT(continuation::follow_max_turn_degrees, 30);
  const auto f = continuation::follow_attached(problem, report, "x", *newton, options);
  ASSERT_GE(f.branch.points.size(), 5u) << f.message;
  EXPECT_EQ(f.branch.reason, continuation::StopReason::bound_reached) << f.message;
  EXPECT_NEAR(f.branch.points.front().x[0], c, 1e-12);
  EXPECT_NEAR(f.branch.points.back().x[0], 2.0, 1e-9);
  double previous = 0;
  for (const auto& p : f.branch.points) {
    const double x = p.x[0], lambda = p.x[1];
    EXPECT_GE(x, previous);
    EXPECT_LE(std::abs(lambda - 1 - CorneredAttachedLine::g(x)), 1e-10 / x) << "x " << x;
    previous = x;
  }
}

// branch_points.csv: the observables, dimension, the problem's description columns, the angle.
TEST(BranchPoints, TableHasTheDocumentedColumns) {
  const algebraic::Transcritical problem;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  continuation::ContinuationHooks hooks;
  int reported = 0;
  hooks.on_branch_point = [&](const continuation::BranchPointReport&) { ++reported; };
  hooks.describe_branch_point = [](const core::Vector& at, const core::Vector& attached) {
    return core::Observables{{"offset", (attached - at).norm()}};
  };
  const Branch b = continuation::pseudo_arclength(problem, vec({0, 0}), vec({0, 1}), *newton,
                                                  detecting(0.13, 20), hooks);
  EXPECT_EQ(reported, 1);
  const core::Table t = continuation::branch_point_table(b);
  ASSERT_EQ(t.rows(), 1u);
  EXPECT_NEAR(t.column("lambda")[0], 1.0, 1e-9);
  EXPECT_EQ(t.column("dimension")[0], 1.0);
  EXPECT_NEAR(t.column("tangent_angle")[0], 45.0, 1e-3);
  // The probe steps h (BranchPointOptions::probe_step) along x and lands on x = lambda - 1:
  // offset h sqrt(2).
  EXPECT_NEAR(t.column("offset")[0], continuation::BranchPointOptions{}.probe_step * std::sqrt(2.0),
              1e-9);
  EXPECT_EQ(t.column("verified")[0], 1.0);
}
