#include "core/jacobians/jacobian_check.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "core/jacobians/finite_difference.hpp"

namespace backbone::core {

namespace {

JacobianComparison compare(const Matrix& analytic, Matrix fd) {
  JacobianComparison c;
  const Eigen::Index n = analytic.cols();
  c.column_absolute_error = Vector::Zero(n);
  c.column_relative_error = Vector::Zero(n);
  const double floor = std::sqrt(std::numeric_limits<double>::epsilon()) *
                           (analytic.size() > 0 ? analytic.cwiseAbs().maxCoeff() : 0.0) +
                       std::numeric_limits<double>::min();
  for (Eigen::Index j = 0; j < n; ++j) {
    if (analytic.rows() == 0) break;
    Eigen::Index row = 0;
    const double err = (analytic.col(j) - fd.col(j)).cwiseAbs().maxCoeff(&row);
    c.column_absolute_error[j] = err;
    c.column_relative_error[j] = err / std::max(analytic.col(j).cwiseAbs().maxCoeff(), floor);
    if (err > c.max_absolute_error || c.worst_row < 0) {
      c.max_absolute_error = err;
      c.worst_row = static_cast<int>(row);
      c.worst_column = static_cast<int>(j);
    }
  }
  c.max_relative_error = n > 0 ? c.column_relative_error.maxCoeff() : 0.0;
  c.finite_difference = std::move(fd);
  return c;
}

}  // namespace

JacobianCheck check_jacobian(const Problem& problem, const Vector& x, int threads) {
  JacobianCheck check;
  check.status = problem.jacobian(x, check.analytic);
  if (check.status != EvalStatus::ok) return check;
  FiniteDifferenceOptions fd;
  fd.threads = threads;
  for (auto scheme :
       {FiniteDifferenceOptions::Scheme::forward, FiniteDifferenceOptions::Scheme::central}) {
    fd.scheme = scheme;
    Matrix J;
    check.status = finite_difference_jacobian(problem, x, J, fd);
    if (check.status != EvalStatus::ok) return check;
    (scheme == FiniteDifferenceOptions::Scheme::forward ? check.forward : check.central) =
        compare(check.analytic, std::move(J));
  }
  return check;
}

std::string JacobianCheck::summary() const {
  if (status != EvalStatus::ok) return fmt::format("jacobian check: {}", to_string(status));
  return fmt::format(
      "jacobian check {}x{}: forward max relative error {:.2e} (worst entry ({}, {}), abs "
      "{:.2e}), central {:.2e} (worst entry ({}, {}), abs {:.2e})",
      analytic.rows(), analytic.cols(), forward.max_relative_error, forward.worst_row,
      forward.worst_column, forward.max_absolute_error, central.max_relative_error,
      central.worst_row, central.worst_column, central.max_absolute_error);
}

}  // namespace backbone::core
