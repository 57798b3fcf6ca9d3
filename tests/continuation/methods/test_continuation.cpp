// Pseudo-arclength and natural continuation on algebraic curves with known shape: folds,
// closed curves, failures that must end the branch cleanly, and what both loops share (scaled
// units of the arclength column, landing on bounds, reject_point at the first point, the
// verifier's settings).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "continuation/methods/natural.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "continuation/methods/switching.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "problems/algebraic/algebraic.hpp"
#include "tests/continuation/test_support.hpp"

using namespace backbone;
using continuation::Branch;
using continuation::StopReason;
using continuation_tests::vec;

namespace {

continuation::ContinuationOptions quick(int points) {
  continuation::ContinuationOptions o;
  o.ds = 0.05;
  o.ds_max = 0.2;
  o.max_points = points;
  o.rank_check_every = 5;
  return o;
}

// The fold curve, but the residual becomes NaN once x passes a threshold.
class PoisonedFold : public algebraic::FoldCurve {
 public:
  explicit PoisonedFold(double threshold) : threshold_(threshold) {}

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    FoldCurve::compute_residual(x, r);
    if (x[0] > threshold_) r[0] = std::numeric_limits<double>::quiet_NaN();
    return core::EvalStatus::ok;
  }

 private:
  double threshold_;
};

// The unit circle in units that grow with |y|: 1 + y^2 for both unknowns and the equation
// (continuation::LocalScale).
class CircleInGrowingUnits : public algebraic::Circle, public continuation::LocalScale {
 public:
  core::Vector local_scale_factor(const core::Vector& x) const override {
    return core::Vector::Constant(2, 1 + x[1] * x[1]);
  }
  core::Vector local_residual_factor(const core::Vector& x) const override {
    return core::Vector::Constant(1, 1 + x[1] * x[1]);
  }
};

}  // namespace

class BothBackends : public ::testing::TestWithParam<const char*> {};

// x^2 + lambda = 1 from x = -1.5 with x increasing: lambda rises to 1 at the fold x = 0 and
// falls again. The branch must pass the fold without turning back (x strictly increasing).
TEST_P(BothBackends, PassesTheFoldWithoutReversing) {
  algebraic::FoldCurve fold;
  auto newton = core::make_corrector(GetParam(), core::NewtonOptions{});
  Branch b =
      continuation::pseudo_arclength(fold, vec(-1.5, -1.25), vec(1.0, 0.0), *newton, quick(40));
  ASSERT_EQ(b.reason, StopReason::max_points) << b.message;
  ASSERT_EQ(b.points.size(), 40u);
  double lambda_max = -1e9;
  for (std::size_t i = 1; i < b.points.size(); ++i) {
    EXPECT_GT(b.points[i].x[0], b.points[i - 1].x[0]) << "reversed at point " << i;
    EXPECT_GT(b.points[i].arclength, b.points[i - 1].arclength);
    EXPECT_LE(b.points[i].residual, 1e-10);
    lambda_max = std::max(lambda_max, b.points[i].x[1]);
  }
  EXPECT_LT(b.points.front().x[1], 0.0);
  EXPECT_GT(b.points.back().x[0], 0.5);  // well past the fold
  EXPECT_LT(b.points.back().x[1], 0.9);  // lambda came down again
  EXPECT_GT(lambda_max, 0.98);           // and went up to the fold value 1 first
  for (const auto& p : b.points)
    if (p.rank) {
      EXPECT_EQ(p.dimension, 1);
    }
}

INSTANTIATE_TEST_SUITE_P(Continuation, BothBackends, ::testing::Values("eigen", "kinsol"));

// The first point's verification waits for the next point, and the loop's units move to the
// first point's own in between. From the guess (0.5, 2) on the hyperplane x = 0.5 the corrected
// point is (0.5, sqrt(0.75)): units 5 at the guess, 1.75 there. The first point is verified in
// the units it was recorded in, so its tangent is found: dimension 1, like every later point.
TEST(PseudoArclength, AFirstPointThatMovesItsUnitsIsVerifiedInItsOwn) {
  const CircleInGrowingUnits circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(6);
  opt.rank_check_every = 1;
  const Branch b =
      continuation::pseudo_arclength(circle, vec(0.5, 2.0), vec(1.0, 0.0), *newton, opt);
  ASSERT_EQ(b.points.size(), 6u) << b.message;
  EXPECT_NEAR(b.points[0].x[1], std::sqrt(0.75), 1e-12);
  for (const auto& p : b.points) {
    EXPECT_NEAR(p.x.norm(), 1.0, 1e-10) << p.index;
    EXPECT_EQ(p.dimension, 1) << p.index;
  }
}

// Along the unit circle from angle 0 to 3 (landing exactly on the bound): the summed chords
// fall short of the arc by ~ s^3/24 per step of arc s <= 0.1, i.e. < 2e-3 over ~30 steps.
TEST(PseudoArclength, FollowsTheCircleToABound) {
  algebraic::Circle circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(200);
  opt.ds_max = 0.1;
  opt.bounds.push_back({"angle", -std::numbers::pi + 1e-9, 3.0});
  Branch b = continuation::pseudo_arclength(circle, vec(1.0, 0.0), vec(0.0, 1.0), *newton, opt);
  EXPECT_EQ(b.reason, StopReason::bound_reached) << b.message;
  EXPECT_NEAR(b.points.back().observable("angle"), 3.0, 1e-9);  // landed on the bound
  EXPECT_LT(b.points.back().arclength, 3.0);
  EXPECT_GT(b.points.back().arclength, 3.0 - 2e-3);
  for (const auto& p : b.points) EXPECT_NEAR(p.x.norm(), 1.0, 1e-10);
}

TEST(Natural, StopsAtTheFoldKeepingItsPoints) {
  algebraic::FoldCurve fold;
  auto newton = core::make_corrector("kinsol", core::NewtonOptions{});
  auto opt = quick(100);
  opt.ds_min = 1e-4;
  Branch b =
      continuation::natural(fold, vec(-1.5, -1.25),
                            continuation::NaturalParameter::of_unknown(1, "lambda"), *newton, opt);
  EXPECT_EQ(b.reason, StopReason::step_floor) << b.message;
  ASSERT_GT(b.points.size(), 5u);
  EXPECT_GT(b.points.back().x[1], 0.99);  // reached the fold lambda = 1 before failing
  EXPECT_LE(b.points.back().x[1], 1.0 + 1e-12);
}

TEST(PseudoArclength, NanResidualEndsTheBranchCleanly) {
  PoisonedFold fold(0.3);
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(100);
  opt.ds_min = 0.01;
  Branch b = continuation::pseudo_arclength(fold, vec(-1.5, -1.25), vec(1.0, 0.0), *newton, opt);
  EXPECT_EQ(b.reason, StopReason::evaluation_failed) << b.message;
  ASSERT_GT(b.points.size(), 10u);
  for (const auto& p : b.points) EXPECT_LE(p.x[0], 0.3);
  EXPECT_NE(b.message.find("evaluation_failed"), std::string::npos) << b.message;
}

TEST(PseudoArclength, NewtonDivergenceEndsAtTheStepFloor) {
  algebraic::FoldCurve fold;
  core::NewtonOptions tight;
  tight.residual_tolerance = 1e-300;  // unreachable: every correction fails after 1 iteration
  tight.max_iterations = 1;
  tight.step_tolerance = 0;
  auto newton = core::make_corrector("eigen", tight);
  auto opt = quick(10);
  // Start exactly on the curve so the first point converges with zero residual.
  Branch b = continuation::pseudo_arclength(fold, vec(0.5, 0.75), vec(1.0, 0.0), *newton, opt);
  EXPECT_TRUE(b.reason == StopReason::step_floor || b.reason == StopReason::newton_failed)
      << b.message;
  EXPECT_LE(b.points.size(), 1u);
  EXPECT_FALSE(b.message.empty());
}

TEST(PseudoArclength, StartThatDoesNotConvergeReportsNewtonFailed) {
  PoisonedFold fold(-10.0);  // NaN everywhere the branch starts
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  Branch b =
      continuation::pseudo_arclength(fold, vec(-1.5, -1.25), vec(1.0, 0.0), *newton, quick(10));
  EXPECT_EQ(b.reason, StopReason::evaluation_failed) << b.message;
  EXPECT_TRUE(b.points.empty());
}

TEST(Options, ValidateNamesTheField) {
  continuation::ContinuationOptions o;
  o.ds_min = 1.0;
  o.ds = 0.1;
  try {
    o.validate();
    FAIL() << "no exception";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), "ds_min");
  }
  o = {};
  o.max_points = 0;
  EXPECT_THROW(o.validate(), core::InputError);
}

TEST(PseudoArclength, SphereIsNotACurve) {
  algebraic::Sphere sphere;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  core::Vector x(3);
  x << 1, 0, 0;
  EXPECT_THROW(
      continuation::pseudo_arclength(sphere, x, core::Vector::Unit(3, 1), *newton, quick(5)),
      core::InputError);
}

namespace {

// The unit circle with its first unknown in millimetres (x0 = 1000 cos, x1 = sin): the same
// curve in other units, reporting them through typical_scale. Observables "angle".
class MillimetreCircle : public core::Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  core::Vector typical_scale() const override { return vec(1000.0, 1.0); }
  core::Observables observables(const core::Vector& x) const override {
    return {{"angle", std::atan2(x[1], x[0] / 1000.0)}};
  }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(1);
    r[0] = (x[0] / 1000.0) * (x[0] / 1000.0) + x[1] * x[1] - 1.0;
    return core::EvalStatus::ok;
  }
};

// x^2 + y^2 = 1 written twice, once scaled: 2 equations of rank 1 in 2 unknowns. A consistent
// overdetermined system, like a shooting residual sampled on more test functions than unknowns.
class DoubledCircle : public core::Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 2; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"angle", std::atan2(x[1], x[0])}};
  }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(2);
    r[0] = x.squaredNorm() - 1.0;
    r[1] = 3.0 * r[0];
    return core::EvalStatus::ok;
  }
};

}  // namespace

// Scaled unknowns make the branch independent of the units: the millimetre circle traced with
// the same dimensionless ds gives the same angles as the unit circle, step for step. Unscaled,
// a ds of 0.05 would be 0.05 mm and the branch would crawl.
TEST(PseudoArclength, ScaledUnknownsMakeTheBranchUnitFree) {
  algebraic::Circle circle;
  MillimetreCircle mm;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const auto opt = quick(40);
  const Branch a = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  const Branch b = continuation::pseudo_arclength(mm, vec(1000, 0), vec(0, 1), *newton, opt);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    // Same steps: Circle has an analytic Jacobian, the mm circle a forward-difference one
    // (relative error ~1e-8), so tangents and hence points along the curve differ by about
    // ds * 1e-8 per step (measured 2e-10 rad after 5 steps); 1e-6 over 40 steps leaves room
    // while a unit-dependent step (angle steps 1000x smaller) would fail by far.
    EXPECT_NEAR(a.points[i].observable("angle"), b.points[i].observable("angle"), 1e-6) << i;
    EXPECT_NEAR(b.points[i].x[0], 1000 * a.points[i].x[0], 1e-3) << i;  // returned in mm
  }
  auto raw = opt;
  raw.scale_unknowns = false;
  const Branch c = continuation::pseudo_arclength(mm, vec(1000, 0), vec(0, 1), *newton, raw);
  // Unscaled, 40 steps of at most ds_max = 0.2 "mm + 1" cannot go far round: the angle after
  // the same number of points is smaller than the scaled run's (measured 1.5 vs 4.6 rad of
  // arclength); the comparison only needs c to lag.
  EXPECT_LT(c.points.back().arclength / 1000, a.points.back().arclength);
}

// A point the independent check rejects is retried with a smaller step and never recorded;
// when no step passes, the branch ends at the step floor and says why.
TEST(PseudoArclength, RejectedPointsAreRetriedAndNeverRecorded) {
  algebraic::Circle circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  continuation::ContinuationHooks hooks;
  int rejections = 0;
  hooks.reject_point = [](const core::Vector& x) {
    return x[1] > 0.5 ? std::string("y above 0.5") : std::string();
  };
  hooks.on_attempt = [&](const continuation::StepAttempt& a) {
    if (!a.rejection.empty()) ++rejections;
  };
  const Branch b =
      continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, quick(200), hooks);
  EXPECT_EQ(b.reason, StopReason::step_floor) << b.message;
  EXPECT_NE(b.message.find("point rejected: y above 0.5"), std::string::npos) << b.message;
  EXPECT_GT(rejections, 0);
  for (const auto& p : b.points) EXPECT_LE(p.x[1], 0.5);
  // It got as close to the limit as ds_min allows: the last point is within a step of it.
  EXPECT_GT(b.points.back().x[1], 0.5 - 1e-6);
}

// A consistent overdetermined system is traced by least-squares Newton (eigen) like a square
// one; KINSOL, square-only, says so instead of iterating.
TEST(PseudoArclength, ConsistentOverdeterminedSystemIsACurve) {
  DoubledCircle doubled;
  algebraic::Circle circle;
  auto eigen = core::make_corrector("eigen", core::NewtonOptions{});
  const Branch a = continuation::pseudo_arclength(doubled, vec(1, 0), vec(0, 1), *eigen, quick(30));
  const Branch b = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *eigen, quick(30));
  ASSERT_EQ(a.points.size(), 30u) << a.message;
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_NEAR(a.points[i].x.norm(), 1.0, 1e-10);
    if (a.points[i].dimension >= 0) {
      EXPECT_EQ(a.points[i].dimension, 1) << i;  // rank 1 of 2
    }
  }
  EXPECT_NEAR(a.points.back().observable("angle"), b.points.back().observable("angle"), 1e-6);
  auto kinsol = core::make_corrector("kinsol", core::NewtonOptions{});
  const Branch k = continuation::pseudo_arclength(doubled, vec(1, 0), vec(0, 1), *kinsol, quick(5));
  EXPECT_EQ(k.reason, StopReason::newton_failed);
  EXPECT_NE(k.message.find("square"), std::string::npos) << k.message;
}

// The paper's strategy on x^2 + lambda = 1: natural in lambda stalls at the fold lambda = 1,
// pseudo-arclength takes over from there and goes round it; one branch, numbering and
// arclength continuous, every point on the curve, x increasing throughout (no turning back).
TEST(NaturalThenArclength, PassesTheFoldWhereNaturalStalls) {
  algebraic::FoldCurve fold;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(60);
  opt.ds_min = 1e-4;
  std::vector<int> reported;
  continuation::ContinuationHooks hooks;
  hooks.on_point = [&](const continuation::BranchPoint& p) { reported.push_back(p.index); };
  const continuation::SwitchingBranch s = continuation::natural_then_arclength(
      fold, vec(-1.5, -1.25), continuation::NaturalParameter::of_unknown(1, "lambda"), *newton, opt,
      hooks);
  const Branch& b = s.branch;
  ASSERT_GT(s.switch_index, 5) << b.message;
  EXPECT_EQ(b.reason, StopReason::max_points) << b.message;
  ASSERT_EQ(b.points.size(), 60u);
  ASSERT_EQ(reported.size(), 60u);  // the restart point is not reported twice
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    const auto& p = b.points[i];
    EXPECT_EQ(p.index, static_cast<int>(i));
    EXPECT_EQ(reported[i], static_cast<int>(i));
    EXPECT_NEAR(p.x[0] * p.x[0] + p.x[1], 1.0, 1e-9) << i;  // Newton tolerance 1e-10
    if (i > 0) {
      EXPECT_GT(p.x[0], b.points[i - 1].x[0]) << i;
      EXPECT_GT(p.arclength, b.points[i - 1].arclength) << i;
    }
  }
  EXPECT_GT(b.points.back().x[0], 0.0);  // past the fold at x = 0
  EXPECT_NE(b.message.find("pseudo-arclength from point"), std::string::npos) << b.message;
}

// Natural continuation of the consistent overdetermined circle (2 equations of rank 1): the
// tangent predictor solves the bordered system of m + 1 = 3 rows by least squares (it once
// assumed n rows and wrote past the right-hand side).
TEST(Natural, ConsistentOverdeterminedSystem) {
  DoubledCircle doubled;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(15);
  opt.ds = opt.ds_max = 0.05;
  const Branch b = continuation::natural(
      doubled, vec(1, 0), continuation::NaturalParameter::of_unknown(1, "y"), *newton, opt);
  ASSERT_EQ(b.points.size(), 15u) << b.message;
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    EXPECT_NEAR(b.points[i].x.norm(), 1.0, 1e-10) << i;
    EXPECT_NEAR(b.points[i].x[1], 0.05 * static_cast<double>(i), 1e-12) << i;  // y = i ds
  }
}

// A cancel request is polled before each step: both loops end with StopReason::cancelled and
// keep the points made so far.
TEST(Continuation, CancelRequestEndsBothLoopsKeepingThePoints) {
  algebraic::Circle circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  int points = 0;
  continuation::ContinuationHooks hooks;
  hooks.on_point = [&](const continuation::BranchPoint&) { ++points; };
  hooks.cancel_requested = [&] { return points >= 5; };
  const Branch a =
      continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, quick(50), hooks);
  EXPECT_EQ(a.reason, StopReason::cancelled) << a.message;
  EXPECT_EQ(a.points.size(), 5u);
  points = 0;
  const Branch b =
      continuation::natural(circle, vec(1, 0), continuation::NaturalParameter::of_unknown(1, "y"),
                            *newton, quick(50), hooks);
  EXPECT_EQ(b.reason, StopReason::cancelled) << b.message;
  EXPECT_EQ(b.points.size(), 5u);
  EXPECT_NE(b.message.find("cancelled after 5 points"), std::string::npos) << b.message;
}

namespace {

// Checks a branch on a curve that is the unit circle in scaled unknowns (Circle, or the
// millimetre circle once scaled): every arclength increment must be the chord 2 sin(dtheta / 2)
// between consecutive points, in the scaled, dimensionless units. Points are on the circle to
// Newton's tolerance (|z|^2 - 1 <= 1e-10, a radial error <= 5e-11), so a chord is exact to
// ~1e-10: 1e-9 leaves room. An arclength in raw unknowns (millimetres) would be off by ~1000x.
// Returns the largest angle step, for the chord-vs-arc bound.
double expect_chords_of_the_unit_circle(const Branch& b) {
  double largest = 0;
  for (std::size_t i = 1; i < b.points.size(); ++i) {
    const double dtheta = b.points[i].observable("angle") - b.points[i - 1].observable("angle");
    largest = std::max(largest, std::abs(dtheta));
    EXPECT_NEAR(b.points[i].arclength - b.points[i - 1].arclength, 2 * std::sin(dtheta / 2), 1e-9)
        << "point " << i;
  }
  return largest;
}

// Arc length from angle 0 to 3 by chords of at most `largest` radians: each chord of an arc s
// is short by s^3 / 24 + O(s^5), so the sum falls short of 3 by at most largest^2 / 24 * 3.
void expect_arc_to_three(const Branch& b, double largest) {
  ASSERT_FALSE(b.points.empty());
  EXPECT_LE(b.points.back().arclength, 3.0 + 1e-9);
  EXPECT_GE(b.points.back().arclength, 3.0 - largest * largest / 24 * 3 - 1e-9);
}

continuation::ContinuationOptions to_angle_three() {
  auto opt = quick(200);
  opt.ds_max = 0.1;
  opt.bounds.push_back({"angle", -std::numbers::pi + 1e-9, 3.0});
  return opt;
}

}  // namespace

// One arclength for both loops: on the millimetre circle (unit circle in scaled unknowns, so
// the arc from angle 0 to 3 has length exactly 3), pseudo-arclength and natural continuation in
// the angle both report chords in scaled units, both land on the bound angle = 3 (Newton
// tolerance 1e-10 on the bound row (angle - 3) / 3: 1e-9), and both totals are within the
// chord-vs-arc bound of 3 (measured 2.9987903 and 2.9987931: chords of ~0.1 rad, 1.2e-3 short).
TEST(Continuation, BothLoopsMeasureTheSameArcInScaledUnits) {
  MillimetreCircle mm;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const auto opt = to_angle_three();
  const Branch arc = continuation::pseudo_arclength(mm, vec(1000, 0), vec(0, 1), *newton, opt);
  const Branch nat = continuation::natural(
      mm, vec(1000, 0), continuation::NaturalParameter::of_observable("angle"), *newton, opt);
  for (const Branch* b : {&arc, &nat}) {
    EXPECT_EQ(b->reason, StopReason::bound_reached) << b->message;
    ASSERT_GT(b->points.size(), 20u) << b->message;
    EXPECT_NEAR(b->points.back().observable("angle"), 3.0, 1e-9) << b->message;
    expect_arc_to_three(*b, expect_chords_of_the_unit_circle(*b));
  }
  std::cout << std::setprecision(10) << "[ measured ] arclength pseudo-arclength "
            << arc.points.back().arclength << ", natural " << nat.points.back().arclength << "\n";
}

// Natural continuation lands on a bound of another observable like pseudo-arclength does:
// x^2 + lambda = 1 stepped in lambda from x = -1.5 (x rises) with x <= -0.5 ends on x = -0.5,
// lambda = 0.75 (Newton tolerance 1e-10 on the rows F and (x + 0.5) / 0.5: 1e-9). Without
// land_on_bounds it stops at its last point inside.
TEST(Natural, LandsOnTheBound) {
  algebraic::FoldCurve fold;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(100);
  opt.bounds.push_back({"x", -10.0, -0.5});
  const auto lambda = continuation::NaturalParameter::of_unknown(1, "lambda");
  const Branch b = continuation::natural(fold, vec(-1.5, -1.25), lambda, *newton, opt);
  EXPECT_EQ(b.reason, StopReason::bound_reached) << b.message;
  ASSERT_GT(b.points.size(), 3u);
  EXPECT_NEAR(b.points.back().x[0], -0.5, 1e-9);
  EXPECT_NEAR(b.points.back().x[1], 0.75, 1e-9);
  EXPECT_NE(b.message.find("lies on it"), std::string::npos) << b.message;
  for (std::size_t i = 1; i < b.points.size(); ++i)
    EXPECT_GT(b.points[i].x[0], b.points[i - 1].x[0]) << i;
  opt.land_on_bounds = false;
  const Branch short_of = continuation::natural(fold, vec(-1.5, -1.25), lambda, *newton, opt);
  EXPECT_EQ(short_of.reason, StopReason::bound_reached);
  EXPECT_LT(short_of.points.back().x[0], -0.5);
  EXPECT_EQ(short_of.points.size() + 1, b.points.size());
}

// The first point goes through reject_point in both loops, in the problem's own unknowns
// (millimetres here): a check that refuses the start ends the branch before any point.
TEST(Continuation, FirstPointGoesThroughRejectPointInBothLoops) {
  MillimetreCircle mm;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  std::vector<core::Vector> asked;
  int rejected_attempts = 0;
  continuation::ContinuationHooks hooks;
  hooks.reject_point = [&](const core::Vector& x) {
    asked.push_back(x);
    return x[1] < 0.01 ? std::string("too close to angle 0") : std::string();
  };
  hooks.on_attempt = [&](const continuation::StepAttempt& a) {
    if (a.point == 0 && !a.rejection.empty() && !a.accepted) ++rejected_attempts;
  };
  const auto opt = quick(20);
  const Branch arc =
      continuation::pseudo_arclength(mm, vec(1000, 0), vec(0, 1), *newton, opt, hooks);
  const Branch nat = continuation::natural(mm, vec(1000, 0),
                                           continuation::NaturalParameter::of_observable("angle"),
                                           *newton, opt, hooks);
  for (const Branch* b : {&arc, &nat}) {
    EXPECT_EQ(b->reason, StopReason::newton_failed) << b->message;
    EXPECT_TRUE(b->points.empty());
    EXPECT_NE(b->message.find("too close to angle 0"), std::string::npos) << b->message;
  }
  ASSERT_EQ(asked.size(), 2u);
  for (const core::Vector& x : asked) EXPECT_NEAR(x[0], 1000.0, 1e-6);  // millimetres
  EXPECT_EQ(rejected_attempts, 2);
}

// natural_then_arclength adds consistent numbers: on the millimetre circle, natural in y stalls
// at the fold y = 1 (angle pi / 2), pseudo-arclength goes on to the bound angle = 3; every
// increment, across the switch too, is the chord in scaled units, and the total is the arc 3 to
// the chord-vs-arc bound.
TEST(NaturalThenArclength, AddsArclengthInTheSameUnits) {
  MillimetreCircle mm;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = to_angle_three();
  opt.ds_min = 1e-4;
  const continuation::SwitchingBranch s = continuation::natural_then_arclength(
      mm, vec(1000, 0), continuation::NaturalParameter::of_unknown(1, "y"), *newton, opt);
  const Branch& b = s.branch;
  ASSERT_GT(s.switch_index, 3) << b.message;
  EXPECT_EQ(b.reason, StopReason::bound_reached) << b.message;
  EXPECT_LT(b.points[s.switch_index - 1].observable("angle"), std::numbers::pi / 2 + 1e-6);
  EXPECT_NEAR(b.points.back().observable("angle"), 3.0, 1e-9);
  expect_arc_to_three(b, expect_chords_of_the_unit_circle(b));
}

// The quadratic predictor on the unit circle at fixed steps of 0.3 rad: the tangent predictor
// lands ds^2 / 2 = 0.045 off the circle, the quadratic one, whose curvature estimate from the
// previous chord is exact up to O(ds), O(ds^3) ~ 1e-2 x that. Every point is on the circle
// (the oracle |x| = 1), and the quadratic branch needs fewer Newton iterations after point 1
// (point 1 has no previous point: both predict by the tangent).
TEST(Continuation, QuadraticPredictorStartsCloserOnACircle) {
  algebraic::Circle circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(12);
  opt.ds = opt.ds_max = opt.ds_min = 0.3;
  opt.rank_check_every = 0;
  int iterations[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    opt.predictor = k == 0 ? continuation::Predictor::tangent : continuation::Predictor::quadratic;
    const Branch b = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
    ASSERT_EQ(b.points.size(), 12u) << b.message;
    for (const auto& p : b.points) EXPECT_NEAR(p.x.norm(), 1.0, 1e-10);
    for (std::size_t i = 2; i < b.points.size(); ++i)
      iterations[k] += b.points[i].newton_iterations;
  }
  EXPECT_LT(iterations[1], iterations[0]) << iterations[0];
  EXPECT_EQ(continuation::parse_predictor("quadratic"), continuation::Predictor::quadratic);
  EXPECT_STREQ(continuation::to_string(continuation::Predictor::quadratic), "quadratic");
}

// The rank verification runs with the corrector options.verification describes: probes 0.05
// along the circle's tangent start 1.25e-3 off the circle, and one Newton iteration (quadratic:
// to ~1e-6) cannot reach the verifier's 1e-10, while the default 60 can (3 iterations). A
// branch of one point is probed. On a longer branch every point has a neighbour that verifies
// its tangent (a chord of 0.1 rad leaves it by tan 0.05 of its length, within drift_ratio 0.1),
// whatever the corrector: point 0 by point 1, the others by the point before.
TEST(Continuation, VerificationUsesTheVerifyOptionsCorrector) {
  algebraic::Circle circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(6);
  opt.rank_check_every = 1;
  opt.verification.step = 0.05;
  opt.ds_max = 0.1;  // chords of at most 0.1 rad (at 0.2 the drift would be tan 0.1 > 0.1)
  const Branch verified =
      continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  opt.verification.max_iterations = 1;
  const Branch capped = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  ASSERT_EQ(verified.points.size(), 6u);
  ASSERT_EQ(capped.points.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(verified.points[i].dimension, 1) << i;
    EXPECT_EQ(capped.points[i].dimension, 1) << i;
  }
  opt.max_points = 1;
  const Branch alone_capped =
      continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  opt.verification.max_iterations = core::VerifyOptions{}.max_iterations;
  const Branch alone = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  ASSERT_EQ(alone_capped.points.size(), 1u);
  ASSERT_EQ(alone.points.size(), 1u);
  EXPECT_EQ(alone_capped.points[0].dimension, 0);
  EXPECT_EQ(alone.points[0].dimension, 1);
}

// The first point's tangent is verified by the second point, at no evaluation of its own: the
// residual evaluations of point 0 are those of its correction alone (the guess and the
// corrected point), where a probe adds at least a stepped point and its correction.
TEST(Continuation, TheFirstPointIsVerifiedByTheSecond) {
  algebraic::Circle circle;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(3);
  opt.rank_check_every = 1;
  const Branch two = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  opt.max_points = 1;
  const Branch one = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  ASSERT_EQ(two.points.size(), 3u);
  ASSERT_EQ(one.points.size(), 1u);
  EXPECT_EQ(two.points[0].dimension, 1);
  EXPECT_EQ(one.points[0].dimension, 1);
  EXPECT_LT(two.points[0].residual_evaluations, one.points[0].residual_evaluations);
}

namespace {

// The line y = x, whose solutions end at x = 1: beyond, F cannot be evaluated (the domain of a
// problem that ends at a nonsmooth edge, as a family of warps does where a slope vanishes).
// Observable room = 1 - x.
class EndingLine : public core::Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"room", 1 - x[0]}};
  }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    if (x[0] > 1) return core::EvalStatus::failed;
    r.resize(1);
    r[0] = x[1] - x[0];
    return core::EvalStatus::ok;
  }
};

}  // namespace

// The branch stalls at the edge: the shrinking steps bring its last point within a few ds_min
// (1e-8 scaled) of x = 1 before ds falls below ds_min, and the last attempt fails to evaluate.
// With a boundary on `room` that admits it (1e-6), that is the planned end boundary_reached;
// without one, or with one it does not reach (1e-12, below the stall's distance), it stays
// evaluation_failed, an early end.
TEST(Continuation, AStallAtTheBoundaryIsAPlannedEnd) {
  EndingLine line;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(200);
  opt.ds = opt.ds_max = 0.1;
  opt.rank_check_every = 0;
  const Branch plain = continuation::pseudo_arclength(line, vec(0, 0), vec(1, 1), *newton, opt);
  EXPECT_EQ(plain.reason, continuation::StopReason::evaluation_failed);
  EXPECT_TRUE(plain.ended_early());
  const double room = 1 - plain.points.back().x[0];
  EXPECT_LT(room, 1e-6);
  EXPECT_GT(room, 1e-12);
  opt.boundary = {"room", 1e-6};
  const Branch ended = continuation::pseudo_arclength(line, vec(0, 0), vec(1, 1), *newton, opt);
  EXPECT_EQ(ended.reason, continuation::StopReason::boundary_reached);
  EXPECT_FALSE(ended.ended_early());
  EXPECT_EQ(ended.points.size(), plain.points.size());
  opt.boundary = {"room", 1e-12};
  const Branch short_of = continuation::pseudo_arclength(line, vec(0, 0), vec(1, 1), *newton, opt);
  EXPECT_EQ(short_of.reason, continuation::StopReason::evaluation_failed);
  opt.boundary = {"room", -1};
  EXPECT_THROW(opt.validate(), core::InputError);
}

namespace {

// The unit circle whose continuation norm counts both unknowns `weight` times (step_weights).
class WeightedCircle : public core::Problem {
 public:
  explicit WeightedCircle(core::Vector weights) : weights_(std::move(weights)) {}
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  core::Vector step_weights() const override { return weights_; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(1);
    r[0] = x.squaredNorm() - 1.0;
    return core::EvalStatus::ok;
  }

 private:
  core::Vector weights_;
};

}  // namespace

// Chord corrections (continuation/README.md 'Chord corrections') change the cost, not the
// curve: on the unit circle at ds 0.05 a chord step on the previous point's Jacobian contracts
// by about ds * curvature = 0.05, so every correction is chord steps only and the points are
// the ones a fresh-Jacobian run finds, within the Newton tolerance (|F| <= 1e-10 and
// |grad F| = 2: 5e-11 from the curve each, 1e-9 allows the difference to accumulate along the
// arclength). Each point then costs one Jacobian (its tangent) instead of one per iteration.
TEST(PseudoArclength, ChordCorrectionsGiveTheSameCurveWithFewerJacobians) {
  const WeightedCircle circle(vec(1, 1));
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(30);
  opt.ds = opt.ds_max = 0.05;
  opt.chord_corrections = false;
  const long fresh_before = circle.counters().jacobians;
  const Branch fresh = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  const long fresh_jacobians = circle.counters().jacobians - fresh_before;
  opt.chord_corrections = true;
  const long chord_before = circle.counters().jacobians;
  const Branch chord = continuation::pseudo_arclength(circle, vec(1, 0), vec(0, 1), *newton, opt);
  const long chord_jacobians = circle.counters().jacobians - chord_before;
  ASSERT_EQ(fresh.points.size(), 30u) << fresh.message;
  ASSERT_EQ(chord.points.size(), 30u) << chord.message;
  for (std::size_t i = 0; i < fresh.points.size(); ++i) {
    EXPECT_NEAR((fresh.points[i].x - chord.points[i].x).norm(), 0, 1e-9) << i;
    EXPECT_NEAR(chord.points[i].x.norm(), 1, 1e-10) << i;
  }
  EXPECT_LT(chord_jacobians, fresh_jacobians);
  // One per point (tangent; the rank report reuses it) beyond the first point's correction.
  EXPECT_LE(chord_jacobians, 30 + 5);
}

// Step weights change the norm, not the problem: with weights 2 a step of 0.1 is a step of 0.05
// with weights 1, so both runs visit the same points and the weighted arclength is twice the
// other. Not bit for bit: the bordered residual [F; arclength row] is not scaled uniformly, so
// the two Newton runs stop at different iterates within the tolerance |F| <= 1e-10 (distance
// to the curve <= 5e-11 here, |grad F| = 2); measured 5e-12 after 30 steps, 1e-9 allows drift.
TEST(PseudoArclength, StepWeightsScaleTheNormOnly) {
  const WeightedCircle plain(vec(1, 1)), doubled(vec(2, 2));
  const continuation::ScaledProblem view(doubled);
  EXPECT_EQ(view.scale(), vec(0.5, 0.5));  // x = scale .* z: z = w .* x ./ s
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = quick(30);
  opt.ds = opt.ds_max = 0.05;
  const Branch a = continuation::pseudo_arclength(plain, vec(1, 0), vec(0, 1), *newton, opt);
  opt.ds = opt.ds_max = 0.1;
  const Branch b = continuation::pseudo_arclength(doubled, vec(1, 0), vec(0, 1), *newton, opt);
  ASSERT_EQ(a.points.size(), 30u);
  ASSERT_EQ(b.points.size(), 30u);
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_NEAR((a.points[i].x - b.points[i].x).norm(), 0, 1e-9) << i;
    EXPECT_NEAR(b.points[i].arclength, 2 * a.points[i].arclength, 2e-9) << i;
  }
  try {
    const WeightedCircle bad(vec(1, 0));
    const continuation::ScaledProblem rejected(bad);
    FAIL() << "accepted a zero step weight";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), "step_weights");
  }
}
