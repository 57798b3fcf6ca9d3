// Following attached families (continuation/branch_points/follow.hpp) on algebraic curves whose
// attached families are known exactly (problems/algebraic/algebraic.hpp): the switch picks a
// verified probe, orients it so that the chosen observable grows, and the followed branch lies on
// the exact attached family.
#include <gtest/gtest.h>

#include <cmath>

#include "continuation/branch_points/follow.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "core/errors.hpp"
#include "problems/algebraic/algebraic.hpp"
#include "tests/continuation/test_support.hpp"

using namespace backbone;
using continuation::Branch;
using continuation_tests::detecting;
using continuation_tests::vec;

namespace {}  // namespace

TEST(Follow, SelectionParsesNoneAllAndK) {
  using Kind = continuation::FollowSelection::Kind;
  EXPECT_EQ(continuation::parse_follow("none").kind, Kind::none);
  EXPECT_FALSE(continuation::parse_follow("none").selects(1));
  EXPECT_TRUE(continuation::parse_follow("all").selects(7));
  const auto third = continuation::parse_follow("3");
  EXPECT_TRUE(third.selects(3));
  EXPECT_FALSE(third.selects(2));
  for (const char* bad : {"0", "-1", "2x", "", "every"}) {
    try {
      continuation::parse_follow(bad);
      ADD_FAILURE() << bad;
    } catch (const core::InputError& e) {
      EXPECT_EQ(e.key(), "follow") << bad;
    }
  }
}

// x (lambda - 1 - x) = 0 traced along x = 0 crosses x = lambda - 1 at (0, 1). Followed towards
// growing x, every point must lie on x = lambda - 1 with x > 0 and x increasing, up to the
// x <= 2 bound. Newton stops at |x (lambda - 1 - x)| <= 1e-10, so |lambda - 1 - x| <= 1e-10 / x
// (the exact bound, asserted as such); the overdetermined copy (least squares) has the same
// attached line.
TEST(Follow, TranscriticalSwitchesOntoTheExactAttachedLine) {
  for (int copies : {1, 3}) {
    const algebraic::Transcritical problem(copies);
    auto newton = core::make_corrector("eigen", core::NewtonOptions{});
    const Branch traced = continuation::pseudo_arclength(problem, vec({0, 0}), vec({0, 1}), *newton,
                                                         detecting(0.13, 20));
    ASSERT_EQ(traced.branch_points.size(), 1u);
    auto options = detecting(0.1, 60);
    options.ds_max = 0.2;
    options.bounds.push_back({"x", -1.0, 2.0});
    const continuation::FollowedBranch f =
        continuation::follow_attached(problem, traced.branch_points[0], "x", *newton, options);
    ASSERT_TRUE(f.start.has_value());
    ASSERT_GE(f.branch.points.size(), 5u) << f.message;
    EXPECT_EQ(f.branch.reason, continuation::StopReason::bound_reached) << f.message;
    EXPECT_TRUE(f.branch.branch_points.empty());  // detection is off on a followed branch
    double previous = 0;
    for (const auto& p : f.branch.points) {
      const double x = p.x[0], lambda = p.x[1];
      EXPECT_GT(x, previous);
      EXPECT_LE(std::abs(lambda - 1 - x), 1e-10 / x) << "x " << x;
      previous = x;
    }
    // It starts at the probe: one step h (BranchPointOptions::probe_step) along the null
    // direction (1, 0) beyond the traced tangent, corrected onto the line (x unchanged by the
    // hyperplane x = h), and lands on the bound.
    EXPECT_NEAR(f.branch.points.front().x[0], continuation::BranchPointOptions{}.probe_step, 1e-12);
    EXPECT_NEAR(f.branch.points.back().x[0], 2.0, 1e-9);
  }
}

// The start is the probe oriented so that the observable grows: on x = lambda - 1 both x and
// lambda grow, at the rate |dx| / |d(x, lambda)| = 1 / sqrt(2) (the growth reported). An
// observable the problem does not have gives no start.
TEST(Follow, StartIsOrientedByTheObservable) {
  const algebraic::Transcritical problem;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const Branch traced = continuation::pseudo_arclength(problem, vec({0, 0}), vec({0, 1}), *newton,
                                                       detecting(0.13, 20));
  ASSERT_EQ(traced.branch_points.size(), 1u);
  const auto& r = traced.branch_points[0];
  const auto start = continuation::attached_start(problem, r, "x");
  ASSERT_TRUE(start.has_value());
  EXPECT_GT(start->direction[0], 0);  // x grows
  EXPECT_GT(start->direction[1], 0);  // and with it lambda, on x = lambda - 1
  EXPECT_NEAR(start->growth, 1 / std::sqrt(2.0), 1e-6);
  EXPECT_FALSE(continuation::attached_start(problem, r, "no_such_observable").has_value());
}

// The z axis pierces the plane z = 1: a two-dimensional attached family, probed along two
// orthonormal directions of the plane. Following "x" takes the probe along which x changes
// fastest, and the whole followed branch stays in the plane (|z - 1| <= the Newton tolerance
// 1e-10 divided by |x, y| >= the first point's distance, about the probe step 1e-3: 1e-7),
// with x growing to the bound.
TEST(Follow, TwoDimensionalAttachedFamilyStaysInThePlane) {
  const algebraic::AxisAndPlane problem;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const Branch traced = continuation::pseudo_arclength(problem, vec({0, 0, 0.1}), vec({0, 0, 1}),
                                                       *newton, detecting(0.17, 12));
  ASSERT_EQ(traced.branch_points.size(), 1u);
  ASSERT_EQ(traced.branch_points[0].attached_points.size(), 2u);
  auto options = detecting(0.1, 40);
  options.bounds.push_back({"x", -1.0, 1.0});
  const auto f =
      continuation::follow_attached(problem, traced.branch_points[0], "x", *newton, options);
  ASSERT_GE(f.branch.points.size(), 5u) << f.message;
  EXPECT_EQ(f.branch.reason, continuation::StopReason::bound_reached) << f.message;
  for (const auto& p : f.branch.points) EXPECT_LE(std::abs(p.x[2] - 1), 1e-7);
  // The starts by rank: the first changes x fastest, a third does not exist (two probes).
  const auto first = continuation::attached_start(problem, traced.branch_points[0], "x", 0);
  const auto second = continuation::attached_start(problem, traced.branch_points[0], "x", 1);
  ASSERT_TRUE(first && second);
  EXPECT_GE(first->growth, second->growth);
  EXPECT_NE(first->probe, second->probe);
  EXPECT_FALSE(continuation::attached_start(problem, traced.branch_points[0], "x", 2));
  EXPECT_NEAR(f.branch.points.back().x[0], 1.0, 1e-9);
}

// An unverified report (no probe found a family) is not followed.
TEST(Follow, UnverifiedPointIsNotFollowed) {
  const algebraic::Transcritical problem;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  continuation::BranchPointReport r;
  r.x = vec({0, 1});
  const auto f = continuation::follow_attached(problem, r, "x", *newton, detecting(0.1, 10));
  EXPECT_TRUE(f.branch.points.empty());
  EXPECT_FALSE(f.start.has_value());
}
