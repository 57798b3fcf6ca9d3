#include "core/solvers/sparse_least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/jacobians/finite_difference.hpp"

namespace backbone::core {

bool sparse_view(const Matrix& J, Eigen::SparseMatrix<double>& A, std::vector<char>& dense_row) {
  const Eigen::Index m = J.rows(), n = J.cols();
  if (n < SparseLeastSquares::min_columns || m < n) return false;
  // Compressed columns in one pass down the columns (J is column-major).
  std::vector<int> outer(static_cast<std::size_t>(n) + 1, 0), inner;
  std::vector<double> values;
  std::vector<int> row_count(static_cast<std::size_t>(m), 0);
  const long budget = static_cast<long>(m) * n / 8;
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = 0; i < m; ++i)
      if (const double v = J(i, j); v != 0) {
        inner.push_back(static_cast<int>(i));
        values.push_back(v);
        ++row_count[static_cast<std::size_t>(i)];
      }
    if (static_cast<long>(inner.size()) > budget) return false;
    outer[static_cast<std::size_t>(j) + 1] = static_cast<int>(inner.size());
  }
  const int dense_length = static_cast<int>(std::max<Eigen::Index>(16, n / 8));
  dense_row.assign(static_cast<std::size_t>(m), 0);
  int dense_rows = 0;
  for (Eigen::Index i = 0; i < m; ++i)
    if (row_count[static_cast<std::size_t>(i)] > dense_length) {
      dense_row[static_cast<std::size_t>(i)] = 1;
      if (++dense_rows > SparseLeastSquares::max_dense_rows) return false;
    }
  A = Eigen::Map<const Eigen::SparseMatrix<double>>(m, n, static_cast<Eigen::Index>(inner.size()),
                                                    outer.data(), inner.data(), values.data());
  return true;
}

bool factor_shifted_normal(const Eigen::SparseMatrix<double>& A, NormalFactor& factor,
                           double* shift) {
  Eigen::SparseMatrix<double> normal = A.transpose() * A;
  double largest = 0;
  for (Eigen::Index j = 0; j < normal.cols(); ++j) largest = std::max(largest, normal.coeff(j, j));
  if (!(largest > 0) || !std::isfinite(largest)) return false;
  for (Eigen::Index j = 0; j < normal.cols(); ++j) normal.coeffRef(j, j) += 1e-10 * largest;
  if (shift) *shift = 1e-10 * largest;
  factor.compute(normal);
  return factor.info() == Eigen::Success;
}

bool factor_sparse_rows(const Eigen::SparseMatrix<double>& A, const std::vector<char>& dense_row,
                        NormalFactor& factor, double* shift) {
  Eigen::SparseMatrix<double> sparse_rows = A;
  sparse_rows.prune([&](Eigen::Index i, Eigen::Index, double) {
    return !dense_row[static_cast<std::size_t>(i)];
  });
  return factor_shifted_normal(sparse_rows, factor, shift);
}

bool SparseLeastSquares::compute(const Matrix& J, double rank_cutoff, bool damped) {
  const Eigen::Index n = J.cols();
  shift_ = 0;
  const auto reject = [this] {
    a_.resize(0, 0);
    return false;
  };
  std::vector<char> dense_row;
  if (!sparse_view(J, a_, dense_row)) return reject();
  if (!factor_sparse_rows(a_, dense_row, factor_, &factor_shift_)) return reject();
  double largest_column = 0;
  for (Eigen::Index j = 0; j < n; ++j) largest_column = std::max(largest_column, a_.col(j).norm());
  // sigma_min from above: two steps of inverse iteration on J^T J from a fixed start
  // (|| (J^T J)^-1 z || / ||z|| <= 1 / sigma_min^2), pseudo-random so that no null vector is
  // orthogonal to it by symmetry (ones is, to the difference of two equal columns).
  Vector z(n), y;
  for (Eigen::Index j = 0; j < n; ++j) z[j] = fixed_weight(static_cast<std::uint64_t>(j));
  double estimate = largest_column;
  // Damped, the operator J^T J + mu I differs from the factor's by the dense rows alone (rank
  // k), whatever J's conditioning: the conjugate gradients still end in about k + 2 steps.
  const auto keep_damped = [&] {
    if (!damped) return reject();
    shift_ = factor_shift_;
    return true;
  };
  const double cutoff = rank_cutoff > 0 ? rank_cutoff : 0.0;
  const double margin = std::max(2 * cutoff, 1e-7) * largest_column;
  const double floor = std::max(1.25 * cutoff, 1e-7) * largest_column;
  // Two steps, and, where the estimate lands between the cut-off and twice it (a cut-off far
  // above the normal equations' floor: the tangent's, the rank threshold 1e-5), up to six more
  // while it still falls by 1 % a step: it then sits within that of sigma_min when the next
  // value is not close, and is kept above 1.25 x the cut-off (the contact bar's tangents at
  // N = 1000, 2.1e-5..3e-5 of the largest column after two steps, had fallen to the dense QR).
  double previous = estimate;
  for (int step = 0; step < 8; ++step) {
    if (!normal_solve(z, y, 1e-6)) return keep_damped();
    const double grow = y.norm() / z.norm();
    if (!std::isfinite(grow) || !(grow > 0)) return keep_damped();
    estimate = std::min(estimate, 1.0 / std::sqrt(grow));
    z = y / y.norm();
    if (step < 1) continue;
    if (estimate > margin) return true;
    if (!(estimate > floor)) return keep_damped();
    if (step > 1 && estimate > 0.99 * previous) return true;  // settled above the floor
    previous = estimate;
  }
  return keep_damped();
}

bool SparseLeastSquares::normal_solve(const Vector& g, Vector& y, double relative_tolerance) const {
  const double g_norm = g.norm();
  y = Vector::Zero(g.size());
  if (g_norm == 0) return true;
  Vector r = g, z = factor_.solve(r), p = z;
  double rz = r.dot(z);
  Vector best = y;
  double best_residual = 1.0, previous = 1.0;
  for (int it = 1; it <= max_iterations; ++it) {
    const Vector q = a_.transpose() * (a_ * p) + shift_ * p;
    const double curvature = p.dot(q);
    if (!(curvature > 0) || !std::isfinite(curvature)) break;
    const double alpha = rz / curvature;
    y += alpha * p;
    r -= alpha * q;
    const double residual = r.norm() / g_norm;
    if (residual < best_residual) {
      best_residual = residual;
      best = y;
    }
    // Converged (1e-3 of the tolerance), or within the tolerance and no longer halving: the
    // round-off floor.
    if (residual <= 1e-3 * relative_tolerance ||
        (residual <= relative_tolerance && residual > 0.5 * previous))
      break;
    previous = residual;
    z = factor_.solve(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  y = best;
  return best_residual <= relative_tolerance;
}

bool SparseLeastSquares::solve(const Vector& b, Vector& x) const {
  if (a_.size() == 0 || b.size() != a_.rows()) return false;
  Vector y;
  if (!normal_solve(a_.transpose() * b, y, 1e-11)) return false;
  x = y;
  return true;
}

}  // namespace backbone::core
