// Small helpers shared by the continuation tests: vectors from literals, and the options of a
// fixed-step branch with branch-point detection on.
//
//   const core::Vector x = vec(1.0, 2.0);            // or vec({1.0, 2.0, 3.0})
//   const auto options = detecting(0.1, 40);           // ds = ds_max = 0.1, 40 points
#pragma once

#include <initializer_list>

#include "continuation/options.hpp"
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

}  // namespace backbone::continuation_tests
