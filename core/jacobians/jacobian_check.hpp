// Checks a problem's analytic Jacobian against forward and central finite differences.
//
// For each column j: the largest absolute error max_i |J_ij - FD_ij| and the relative error,
// that absolute error divided by max(||J_:,j||_inf, sqrt(eps) * max_ij |J_ij|) (the floor
// keeps a zero analytic column from turning FD noise into a relative error of 1). The worst
// entry is located for each scheme. Expected sizes, from the step rule of
// finite_difference.hpp: forward ~ sqrt(eps) ~ 1e-8 and central ~ eps^(2/3) ~ 4e-11 relative
// to the derivatives' magnitudes; an error of 1e-3 is a bug, not truncation.
//
//   JacobianCheck check = check_jacobian(problem, x);
//   if (check.status != EvalStatus::ok || check.central.max_relative_error > 1e-6)
//     fmt::print("{}\n", check.summary());   // names the worst entry (row, column)
#pragma once

#include <string>

#include "core/problem.hpp"

namespace backbone::core {

struct JacobianComparison {
  Matrix finite_difference;
  Vector column_absolute_error;  // per column, max over rows
  Vector column_relative_error;  // per column, see the header note for the denominator
  double max_absolute_error = 0;
  double max_relative_error = 0;
  int worst_row = -1;  // entry with the largest absolute error
  int worst_column = -1;
};

struct JacobianCheck {
  EvalStatus status = EvalStatus::ok;  // first non-ok evaluation, if any
  Matrix analytic;                     // Problem::jacobian at x
  JacobianComparison forward;
  JacobianComparison central;
  std::string summary() const;  // one line: worst relative errors and where they occur
};

// threads: passed to the finite-difference evaluations (Problem::compute_residual is const).
JacobianCheck check_jacobian(const Problem& problem, const Vector& x, int threads = 1);

}  // namespace backbone::core
