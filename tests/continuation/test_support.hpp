// Small helpers shared by the continuation tests: vectors from literals, the options of a
// fixed-step branch with branch-point detection on, and a solution set with an edge.
//
//   const core::Vector x = vec(1.0, 2.0);            // or vec({1.0, 2.0, 3.0})
//   const auto options = detecting(0.1, 40);           // ds = ds_max = 0.1, 40 points
//   const HalfPlane half_plane;                        // {z = 0, x >= 0}, J outside on its edge
#pragma once

#include <algorithm>
#include <initializer_list>

#include "continuation/options.hpp"
#include "core/problem.hpp"
#include "core/types.hpp"

namespace backbone::continuation_tests {

inline core::Vector vec(std::initializer_list<double> values) {
  core::Vector v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double x : values) v[i++] = x;
  return v;
}

inline core::Vector vec(double a, double b) {
  return vec({a, b});
}

// A fixed step (ds = ds_max), so that no point lands on a branch point by chance; rank reports
// off, branch-point detection on.
inline continuation::ContinuationOptions detecting(double ds, int points) {
  continuation::ContinuationOptions o;
  o.ds = ds;
  o.ds_max = ds;
  o.max_points = points;
  o.rank_check_every = 0;
  o.branch_points.detect = true;
  return o;
}

// The half plane {z = 0, side x >= 0} of R^3 as the zero set of F = (z, min(side x, 0)): a
// two-dimensional set with an edge at x = 0. With outside_on_edge, J on the edge (side x within
// 1e-12 of 0, as a march's decision within round-off) is the side without solutions (d/dx of the
// second row `side`): its null space is then the edge, the y axis, alone. Else J there is the
// set's own (null space the x and y axes). Observable "inside" = side x, 0 on the edge.
class HalfPlane : public core::Problem {
 public:
  explicit HalfPlane(double side = 1, bool outside_on_edge = true)
      : side_(side), outside_on_edge_(outside_on_edge) {}
  int num_unknowns() const override { return 3; }
  int num_equations() const override { return 2; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"inside", side_ * x[0]}};
  }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(2);
    r << x[2], std::min(side_ * x[0], 0.0);
    return core::EvalStatus::ok;
  }
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override {
    J = core::Matrix::Zero(2, 3);
    J(0, 2) = 1;
    const double inside = side_ * x[0];
    J(1, 0) = (outside_on_edge_ ? inside <= 1e-12 : inside < 0) ? side_ : 0.0;
    return core::EvalStatus::ok;
  }

 private:
  double side_;
  bool outside_on_edge_;
};

}  // namespace backbone::continuation_tests
