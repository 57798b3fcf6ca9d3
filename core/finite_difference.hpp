// Finite-difference Jacobians: the default derivative of every Problem.
//
// Step rule (documented once, used everywhere): column j uses
//     h_j = relative_step * max(|x_j|, typical_scale_j)
// with relative_step = sqrt(machine epsilon) ~ 1.5e-8 for forward differences (truncation
// O(h) balances round-off O(eps/h)) and cbrt(machine epsilon) ~ 6e-6 for central differences
// (truncation O(h^2)). h_j is then rounded so that x_j + h_j is exactly representable.
// Columns are independent: with threads > 1 they are evaluated concurrently
// (Problem::compute_residual is const and must be thread-safe).
//
//   FiniteDifferenceOptions fd; fd.scheme = FiniteDifferenceOptions::Scheme::central;
//   Matrix J;
//   EvalStatus s = finite_difference_jacobian(problem, x, J, fd);
#pragma once

#include "core/problem.hpp"

namespace backbone::core {

struct FiniteDifferenceOptions {
  enum class Scheme { forward, central };
  Scheme scheme = Scheme::forward;
  double relative_step = 0;  // 0: the rule above
  int threads = 1;
};

EvalStatus finite_difference_jacobian(const Problem& problem, const Vector& x, Matrix& J,
                                      const FiniteDifferenceOptions& options = {});

}  // namespace backbone::core
