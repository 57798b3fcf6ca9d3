// The dimension re-check of PointRecorder (continuation/internal/point_recorder.hpp, branch.hpp:
// DimensionFlag): a point of a continuation curve has dimension >= 1, so a verified 0 is probed
// again along the direction the loop knows. Oracles: sets whose dimension is known exactly,
// the x axis of R^3 as the zero set of [y, z^2] (candidate null space {e_x, e_z}: only e_x is
// real, z^2 = h^2 has no root on the hyperplane z = h) and the plane y = 0 (e_x and e_z real).
#include <gtest/gtest.h>

#include "continuation/internal/point_recorder.hpp"
#include "core/rank/rank_report.hpp"
#include "tests/continuation/test_support.hpp"

using namespace backbone;

namespace {

class AxisWithDoubleRoot : public core::Problem {
 public:
  explicit AxisWithDoubleRoot(bool plane) : plane_(plane) {}
  int num_unknowns() const override { return 3; }
  int num_equations() const override { return plane_ ? 1 : 2; }
  std::string name() const override { return plane_ ? "plane" : "axis"; }
  core::Observables observables(const core::Vector&) const override { return {}; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(num_equations());
    r[0] = x[1];
    if (!plane_) r[1] = x[2] * x[2];
    return core::EvalStatus::ok;
  }
  // Exact (a forward difference of z^2 at z = 0 is its step, not 0).
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override {
    J = core::Matrix::Zero(num_equations(), 3);
    J(0, 1) = 1;
    if (!plane_) J(1, 2) = 2 * x[2];
    return core::EvalStatus::ok;
  }

 private:
  bool plane_;
};

core::Vector unit(int i) {
  return core::Vector::Unit(3, i);
}

// A recorded point at the origin whose verification "failed": verified dimension 0 with the
// candidate null space of J (e_x, e_z, rotated by 45 degrees as an SVD basis may be).
continuation::BranchPoint failed_point(const core::Problem& problem) {
  continuation::BranchPoint p;
  p.x = core::Vector::Zero(3);
  core::Matrix J;
  EXPECT_EQ(problem.jacobian(p.x, J), core::EvalStatus::ok);
  core::RankReport report = core::rank_report(J, core::RankOptions{});
  EXPECT_EQ(report.nullity, 2);
  core::Matrix rotated(3, 2);
  rotated.col(0) = (unit(0) + unit(2)).normalized();
  rotated.col(1) = (unit(0) - unit(2)).normalized();
  report.null_directions = rotated;
  report.verified_dimension = 0;
  p.dimension = 0;
  p.rank = report;
  return p;
}

}  // namespace

TEST(PointRecorder, DimensionZeroOnACurveIsRecheckedAlongTheTangent) {
  const AxisWithDoubleRoot axis(false), plane(true);
  const continuation::ContinuationOptions options;
  continuation::PointRecorder on_axis(axis, options), on_plane(plane, options);

  // Along the axis (the curve's tangent): the curve is found, e_z is not real -> 1.
  auto p = failed_point(axis);
  on_axis.recheck_dimension(p, unit(0));
  EXPECT_EQ(p.dimension_flag, continuation::DimensionFlag::rechecked);
  EXPECT_EQ(p.dimension, 1);
  EXPECT_NE(continuation::dimension_warning(p).find("dimension 1"), std::string::npos);

  // A wrong "tangent" (e_z) does not confirm anything: flagged, the dimension left as verified.
  auto q = failed_point(axis);
  on_axis.recheck_dimension(q, unit(2));
  EXPECT_EQ(q.dimension_flag, continuation::DimensionFlag::unconfirmed);
  EXPECT_EQ(q.dimension, 0);
  EXPECT_NE(continuation::dimension_warning(q).find("not to be trusted"), std::string::npos);

  // The plane: the tangent plus the candidate direction orthogonal to it -> 2.
  auto r = failed_point(plane);
  on_plane.recheck_dimension(r, unit(0));
  EXPECT_EQ(r.dimension_flag, continuation::DimensionFlag::rechecked);
  EXPECT_EQ(r.dimension, 2);

  // A point whose verified dimension is already >= 1 is left alone.
  auto s = failed_point(axis);
  s.dimension = 1;
  on_axis.recheck_dimension(s, unit(2));
  EXPECT_EQ(s.dimension_flag, continuation::DimensionFlag::as_verified);
  EXPECT_EQ(s.dimension, 1);
  EXPECT_TRUE(continuation::dimension_warning(s).empty());
}

// On the edge of the half plane (tests/continuation/test_support.hpp, J on its edge the
// outside's) J counts 1 (the edge). With the boundary observable and verify_inside (the
// follows' setting) the point's dimension is verified at a neighbour just inside, found along
// the chord towards the branch's point 0 (the anchor, x = 1): 2, the half plane's, flagged
// inside. The edge's own candidate runs along the edge and finds no neighbour inside, so without
// point 0 the count stays 1; without verify_inside nothing is re-checked.
TEST(PointRecorder, OnTheBoundaryOfItsSetTheDimensionIsVerifiedInside) {
  const continuation_tests::HalfPlane half_plane;  // J on the edge is the outside's
  const core::Vector anchor = unit(0), edge = 0.3 * unit(1);
  continuation::ContinuationOptions options;
  options.boundary = {"inside", 1e-3, true};

  continuation::PointRecorder recorder(half_plane, options);
  const continuation::BranchPoint first = recorder.finish(anchor, 0, 0, 0.0, 0.0, true);
  EXPECT_EQ(first.dimension, 2);
  EXPECT_EQ(first.dimension_flag, continuation::DimensionFlag::as_verified);
  const continuation::BranchPoint on_edge = recorder.finish(edge, 7, 0, 0.1, 1.0, true);
  EXPECT_EQ(on_edge.dimension, 2);
  EXPECT_EQ(on_edge.dimension_flag, continuation::DimensionFlag::inside);
  EXPECT_NE(continuation::dimension_warning(on_edge).find("inside"), std::string::npos);

  continuation::PointRecorder without_anchor(half_plane, options);
  const continuation::BranchPoint alone = without_anchor.finish(edge, 7, 0, 0.1, 1.0, true);
  EXPECT_EQ(alone.dimension, 1);
  EXPECT_EQ(alone.dimension_flag, continuation::DimensionFlag::as_verified);

  continuation::ContinuationOptions only_boundary;
  only_boundary.boundary = {"inside", 1e-3, false};
  continuation::PointRecorder unchecked(half_plane, only_boundary);
  unchecked.finish(anchor, 0, 0, 0.0, 0.0, true);
  EXPECT_EQ(unchecked.finish(edge, 7, 0, 0.1, 1.0, true).dimension, 1);
}
