// Least squares for a Jacobian whose rows are sparse but for a few (core/README.md, 'Newton
// correctors'), in O(nonzeros) instead of the O(m n^2) of a dense QR.
//
// The contact bar's bordered shooting Jacobian at N = 640 (1281 x 641) has about 9 entries per
// row, one dense column (the period) and one dense row (the arclength row); its dense QR takes
// ~100 ms and is 80 % of the trace. Here: J in compressed columns (one pass over the dense
// array), the normal matrix B = A_s^T A_s of its sparse rows A_s (the dense rows left out, so
// that B stays sparse: 32k entries in the Cholesky factor at N = 640 against a 205k-entry
// triangle), a sparse Cholesky factor of B + mu I in approximate-minimum-degree order (mu =
// 1e-10 of B's largest diagonal entry: B alone is singular along a branch's tangent, which the
// arclength row fixes), and the least-squares solution by conjugate gradients on
// J^T J x = J^T b with that factor as the preconditioner, the products taken with J itself. J^T J
// differs from the preconditioner by the dense rows (rank k) and mu I, so the iteration ends in
// about k + 2 steps (3-5 at N = 640, 3 ms for the factor, 0.3 ms per solve; the solutions agree
// with the Householder QR's to 1e-11).
// compute() accepts J only where the dense path would give the same solution: sigma_min(J)
// above 2 x the cut-off of the largest column norm (the first pivot of the COD, which keeps full
// rank when sigma_min is above its cut-off; there the minimum-norm solution is the least-squares
// one), and where the normal equations are safe: sigma_min above 1e-7 of that norm, so that
// conjugate gradients on J^T J reach the solution to about cond(J) eps. sigma_min is estimated
// from above by two steps of inverse iteration on J^T J (each a conjugate-gradient solve) from a
// pseudo-random start, as the dense path estimates it on R^T R; where that lands between the
// cut-off and twice it, by up to six more, and J is kept once the estimate settles (falls by
// less than 1 % a step) above 1.25 times the cut-off.
//
//   SparseLeastSquares ls;
//   if (ls.compute(J, 1e-12)) ls.solve(b, x);   // else a dense QR or COD
#pragma once

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <vector>

#include "core/types.hpp"

namespace backbone::core {

// J (m x n) in compressed columns when sparse enough to pay: n >= SparseLeastSquares::
// min_columns, m >= n, at most n / 8 entries per row on average and at most max_dense_rows
// rows with more than max(16, n / 8) entries, which dense_row marks. false otherwise (A and
// dense_row then mean nothing). Exact zeros of J are left out, every other entry kept.
bool sparse_view(const Matrix& J, Eigen::SparseMatrix<double>& A, std::vector<char>& dense_row);

using NormalFactor =
    Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>;

// The sparse Cholesky factor of A^T A + mu I, mu = 1e-10 of A^T A's largest diagonal entry (A^T A
// alone is singular wherever A has a null direction; the shift keeps its eigenvectors). false
// when A^T A has no positive finite diagonal or the factorisation fails.
// shift, when given, receives mu.
bool factor_shifted_normal(const Eigen::SparseMatrix<double>& A, NormalFactor& factor,
                           double* shift = nullptr);
// The same for A without the rows dense_row marks (as sparse_view fills it): the factor of
// S^T S + mu I, S those other rows, which a few dense rows would fill in.
bool factor_sparse_rows(const Eigen::SparseMatrix<double>& A, const std::vector<char>& dense_row,
                        NormalFactor& factor, double* shift = nullptr);

class SparseLeastSquares {
 public:
  // false (nothing kept) when J is too small or too dense to pay (n < min_columns, more than
  // max_dense_rows rows with more than max(16, n / 8) entries, more than n / 8 entries per row
  // on average), when the factor fails, or when J fails the conditioning tests above.
  // damped: where J passes the sparsity tests but fails the conditioning ones (a rank-deficient
  // J), keep it all the same and solve the damped normal equations (J^T J + mu I) x = J^T b
  // instead, mu the factor's shift: a Levenberg-Marquardt step, which drops the components
  // along singular values far below sqrt(mu) (1e-5 of the largest column norm) where the
  // minimum-norm solution would divide by them (core/README.md, 'Newton correctors').
  bool compute(const Matrix& J, double rank_cutoff, bool damped = false);
  bool is_damped() const { return shift_ > 0; }
  // x minimising |J x - b|; false when the iteration did not converge (then x is unchanged).
  bool solve(const Vector& b, Vector& x) const;
  Eigen::Index cols() const { return a_.cols(); }
  // J as compute() kept it (dense), e.g. for a dense factorisation after a failed solve.
  Matrix matrix() const { return Matrix(a_); }

  static constexpr Eigen::Index min_columns = 64;
  static constexpr int max_dense_rows = 8;
  static constexpr int max_iterations = 40;

 private:
  // Conjugate gradients on J^T J y = g, preconditioned by the factor; y from zero. false when
  // |g - J^T J y| has not fallen to relative_tolerance |g| in max_iterations.
  bool normal_solve(const Vector& g, Vector& y, double relative_tolerance) const;

  Eigen::SparseMatrix<double> a_;  // J, compressed columns
  NormalFactor factor_;
  double factor_shift_ = 0;  // mu of the factor
  double shift_ = 0;         // mu when damped, else 0
};

}  // namespace backbone::core
