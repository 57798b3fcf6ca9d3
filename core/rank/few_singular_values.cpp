#include "core/rank/few_singular_values.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/jacobians/finite_difference.hpp"
#include "core/solvers/sparse_least_squares.hpp"

namespace backbone::core {

// The smallest singular triplet of the tall matrix A (rows >= cols) from the triangular factor R of
// A's Householder QR (sigma(R) = sigma(A)): a Krylov basis of inverse iteration on R^T R from
// `start` (the reference's right vector: the triplet moves little between points), and the
// Rayleigh-Ritz triplet of R on it (the smallest singular triplet of R K, K orthonormal). Plain
// inverse iteration converges as (sigma_1 / sigma_2)^2 per step, which near a branch point of the
// contact bar, where some twenty singular values vanish together, needs hundreds of steps; the Ritz
// triplet of the Krylov space resolves the smallest of the cluster in a few tens of vectors.
// Measured on the 201 x 101 bordered matrix of the contact bar at 100 intervals: the QR takes 0.34
// ms where the thin SVD takes 6 ms, and each vector two triangular solves (~10 us). Converged when
// the triplet's residual |R^T u - sigma v| (a singular value of A lies within it of sigma) is below
// 1e-4 sigma plus 1e-12 |A|_F: the location needs the value to a few digits, and near a root the
// residual stalls at 1e-13..1e-12 |A|_F (the round-off of the basis); false when it is not within
// 40 vectors (at the contact bar's located points, sigma ~ 1e-9 inside a cluster: 6 of 83 calls):
// the caller falls back to the SVD.
bool smallest_singular_triplet(const Matrix& A, const Vector& start, Vector& left, Vector& right,
                               double& sigma) {
  const Eigen::Index n = A.cols();
  if (A.rows() < n || n == 0) return false;
  const Eigen::HouseholderQR<Matrix> qr(A);
  const Matrix R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  if (!(R.diagonal().cwiseAbs().minCoeff() > 0)) return false;
  const double floor = 1e-12 * A.norm();
  const Eigen::Index max_vectors = std::min<Eigen::Index>(n, 40);
  Matrix K(n, max_vectors), RK(n, max_vectors);
  Vector v = start.size() == n && start.norm() > 0 ? Vector(start) : Vector::Ones(n);
  Eigen::Index next_check = 1;
  for (Eigen::Index j = 0; j < max_vectors; ++j) {
    if (j > 0) {
      // One step of inverse iteration on R^T R from the last basis vector.
      v = R.transpose().triangularView<Eigen::Lower>().solve(K.col(j - 1));
      v = R.triangularView<Eigen::Upper>().solve(v);
    }
    if (!v.allFinite()) return false;
    const double before = v.norm();
    for (int pass = 0; pass < 2; ++pass)  // classical Gram-Schmidt, twice
      v -= K.leftCols(j) * (K.leftCols(j).transpose() * v);
    const double norm = v.norm();
    if (!(norm > 1e-12 * before)) return false;  // the space stopped growing: not expected
    K.col(j) = v / norm;
    RK.col(j) = R * K.col(j);
    if (j + 1 != next_check && j + 1 != max_vectors) continue;
    next_check = std::max<Eigen::Index>(next_check + 1, next_check * 3 / 2);
    const Eigen::JacobiSVD<Matrix> small(RK.leftCols(j + 1),
                                         Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::Index last = j;
    sigma = small.singularValues()(last);
    if (!(sigma > 0)) return false;
    Vector candidate = K.leftCols(j + 1) * small.matrixV().col(last);
    candidate.normalize();
    const Vector Rv = R * candidate;
    const double residual = (R.transpose() * (Rv / sigma) - sigma * candidate).norm();
    if (residual <= 1e-4 * sigma + floor) {
      right = candidate;
      left = A * candidate / sigma;
      return true;
    }
  }
  return false;
}

namespace {

// A fixed, well-spread start block (n x k): entries +-(1..2) (fixed_weight), orthonormalised.
Matrix start_block(Eigen::Index n, Eigen::Index k) {
  Matrix X(n, k);
  for (Eigen::Index j = 0; j < k; ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      X(i, j) = fixed_weight(static_cast<std::uint64_t>(j * n + i + 1));
  const Eigen::HouseholderQR<Matrix> qr(X);
  return qr.householderQ() * Matrix::Identity(n, k);
}

// A with A^T A = J^T J, the operator the iteration below works with: R of a Householder QR of J
// (n x n), or, for a sparse J (sparse_least_squares.hpp), J itself with a sparse Cholesky
// factor of J^T J + mu I for the inverse iteration (mu = 1e-10 of its largest diagonal entry:
// the same eigenvectors, J^T J itself being singular wherever there is a null direction).
struct TriangularGram {
  Matrix r;
  Eigen::Index rows() const { return r.rows(); }
  Vector times(const Vector& v) const { return r.triangularView<Eigen::Upper>() * v; }
  Matrix times(const Matrix& x) const { return r.triangularView<Eigen::Upper>() * x; }
  Vector times_transpose(const Vector& u) const {
    return r.triangularView<Eigen::Upper>().transpose() * u;
  }
  Matrix inverse_gram(const Matrix& x) const {
    const auto upper = r.triangularView<Eigen::Upper>();
    return upper.solve(Matrix(upper.transpose().solve(x)));
  }
};

// J sparse but for k <= SparseLeastSquares::max_dense_rows dense rows D (a front whose motion
// depends on every unknown): the factor is of S^T S + mu I, S the other rows, and the dense rows
// join by Woodbury, (M + D^T D)^-1 = M^-1 - Z (I + D Z)^-1 D M^-1 with Z = M^-1 D^T, so that
// J^T J's fill (dense from one dense row) is never formed.
struct SparseGram {
  Eigen::SparseMatrix<double> a;
  NormalFactor factor;
  Matrix d, z;                     // D (k x n) and Z (n x k); empty without dense rows
  Eigen::LLT<Matrix> capacitance;  // I + D Z
  Eigen::Index rows() const { return a.rows(); }
  Vector times(const Vector& v) const { return a * v; }
  Matrix times(const Matrix& x) const { return a * x; }
  Vector times_transpose(const Vector& u) const { return a.transpose() * u; }
  Matrix inverse_gram(const Matrix& x) const {
    Matrix y = factor.solve(x);
    if (d.rows() > 0) y -= z * capacitance.solve(d * y);
    return y;
  }
  // Factors a (all of J) with the rows marked dense set apart; false when that fails.
  bool factor_with_dense_rows(const Matrix& J, const std::vector<char>& dense_row) {
    if (!factor_sparse_rows(a, dense_row, factor)) return false;
    std::vector<Eigen::Index> dense;
    for (std::size_t i = 0; i < dense_row.size(); ++i)
      if (dense_row[i]) dense.push_back(static_cast<Eigen::Index>(i));
    if (dense.empty()) return true;
    d.resize(static_cast<Eigen::Index>(dense.size()), J.cols());
    for (std::size_t r = 0; r < dense.size(); ++r)
      d.row(static_cast<Eigen::Index>(r)) = J.row(dense[r]);
    z = factor.solve(Matrix(d.transpose()));
    capacitance.compute(Matrix::Identity(d.rows(), d.rows()) + d * z);
    return capacitance.info() == Eigen::Success && z.allFinite();
  }
};

// sigma_max of the Gram's operator A (A^T A = J^T J); 0 when the iteration breaks down at once.
template <class Gram>
double largest_singular_value(const Gram& gram, Eigen::Index n) {
  // Golub-Kahan-Lanczos bidiagonalisation of R (fully reorthogonalised), the largest
  // singular value of its bidiagonal, until that moves by less than 1e-10 of itself (at most
  // 60 steps; Lanczos finds the extreme values in a few tens of steps where power iteration on
  // a clustered top of the spectrum takes hundreds, and leaves 0.3 % on the contact bar).
  double sigma_max = 0;
  {
    const int steps = static_cast<int>(std::min<Eigen::Index>(60, n));
    Matrix V(n, steps + 1), U(gram.rows(), steps);
    Vector alpha = Vector::Zero(steps), beta = Vector::Zero(steps);
    V.col(0) = start_block(n, 1).col(0);
    for (int j = 0; j < steps; ++j) {
      Vector u = gram.times(Vector(V.col(j)));
      if (j > 0) u -= beta[j - 1] * U.col(j - 1);
      u -= U.leftCols(j) * (U.leftCols(j).transpose() * u);
      alpha[j] = u.norm();
      if (!(alpha[j] > 0) || !std::isfinite(alpha[j])) break;
      U.col(j) = u / alpha[j];
      Vector w = gram.times_transpose(Vector(U.col(j))) - alpha[j] * V.col(j);
      w -= V.leftCols(j + 1) * (V.leftCols(j + 1).transpose() * w);
      beta[j] = w.norm();
      // The largest eigenvalue of the tridiagonal B^T B (B: alpha on the diagonal, beta above).
      Vector diagonal(j + 1), off(j);
      for (int i = 0; i <= j; ++i) {
        diagonal[i] = alpha[i] * alpha[i] + (i > 0 ? beta[i - 1] * beta[i - 1] : 0.0);
        if (i < j) off[i] = alpha[i] * beta[i];
      }
      Eigen::SelfAdjointEigenSolver<Matrix> tridiagonal;
      tridiagonal.computeFromTridiagonal(diagonal, off, Eigen::EigenvaluesOnly);
      const double estimate = std::sqrt(tridiagonal.eigenvalues()[j]);
      const bool settled = std::abs(estimate - sigma_max) <= 1e-10 * estimate;
      sigma_max = estimate;
      if (settled || !(beta[j] > 1e-15 * estimate)) break;
      V.col(j + 1) = w / beta[j];
    }
  }
  return sigma_max;
}

// The block inverse iteration of smallest_singular_values (below) on the Gram's operator, given
// sigma_max and the threshold.
template <class Gram>
bool smallest_block(const Gram& gram, Eigen::Index n, double sigma_max, double threshold,
                    SmallestSingularValues& out) {
  for (Eigen::Index k = std::min<Eigen::Index>(8, n); 2 * k <= n; k *= 2) {
    Matrix X = start_block(n, k);
    bool converged = false, too_small = false;
    Vector s;
    Matrix W, previous_span;
    int previous_below = -1;
    double previous_kept = 0;
    for (int step = 0; step < 60 && !converged; ++step) {
      Matrix Y = gram.inverse_gram(X);
      if (!Y.allFinite()) return false;
      const Eigen::HouseholderQR<Matrix> block(Y);
      X = block.householderQ() * Matrix::Identity(n, k);
      const Eigen::JacobiSVD<Matrix> ritz(gram.times(X), Eigen::ComputeThinU | Eigen::ComputeThinV);
      s = ritz.singularValues();
      W = X * ritz.matrixV();
      int below = 0;
      for (Eigen::Index i = 0; i < k; ++i) below += s[i] <= threshold ? 1 : 0;
      too_small = below >= k - 1;
      if (too_small) break;
      // The pairs that matter: those at or below the threshold (their span) and the smallest
      // above it (its value). Converged when the span moves by a sine below 1e-10 between two
      // steps and that value by 1e-10 of itself: each step shrinks the error of both by
      // (s / sigma_{k+1})^2, so what is left is below that last move once the ratio is below
      // 1/2 (the block is eight or more wide). (A residual test |R^T u - s w| does not work
      // for the values at the finite-difference noise: u = R w / s divides R w's round-off,
      // eps sigma_max, by s.)
      const Eigen::Index kept = k - 1 - below;
      const Matrix null_span = W.rightCols(below);
      converged =
          below == previous_below && previous_kept > 0 &&
          std::abs(s[kept] - previous_kept) <= 1e-10 * s[kept] &&
          (below == 0 || (previous_span - null_span * (null_span.transpose() * previous_span))
                                 .colwise()
                                 .norm()
                                 .maxCoeff() <= 1e-10);
      previous_below = below;
      previous_kept = s[kept];
      previous_span = null_span;
    }
    if (too_small) continue;
    if (!converged) return false;
    out.largest = sigma_max;
    out.values = s;
    out.right = W;
    return true;
  }
  return false;
}

template <class Gram>
bool smallest_singular_values(const Gram& gram, Eigen::Index n, double relative_threshold,
                              double absolute_threshold, SmallestSingularValues& out) {
  const double sigma_max = largest_singular_value(gram, n);
  if (!(sigma_max > 0) || !std::isfinite(sigma_max)) return false;
  const double threshold = std::max(relative_threshold * sigma_max, absolute_threshold);
  return smallest_block(gram, n, sigma_max, threshold, out);
}

}  // namespace

// The smallest singular values of J (m >= n) and their right vectors, without a full SVD:
// R from a Householder QR of J (J = QR, same singular values and right vectors), sigma_max by
// Lanczos bidiagonalisation of R, the k smallest by block inverse iteration on R^T R (two
// triangular solves per step, the block re-orthonormalised) with a Rayleigh-Ritz step (SVD of
// the n x k R X) each time, converged when the span of the values at or below the threshold
// and the smallest value above it stop moving (below). The block holds k = 8 to start and
// doubles while the values at or below the threshold fill all but one of it, so that it always
// holds one value above the threshold (sigma_kept and the gap). False (the caller takes the
// full SVD) when R is singular to working precision, the block would exceed n / 2, or 60 steps
// do not converge. Measured on the contact bar's mode 1 at N = 160 (321 x 161): 4-7 steps,
// sigma_zero and sigma_kept within 3.4e-6 of the full SVD's (sigma_max's Lanczos estimate),
// the same branch and dimensions; core/README.md, 'Rank reports'. A sparse J (a few dense rows
// allowed) skips the QR: the products are J's, the inverse iteration a sparse Cholesky solve
// (SparseGram); should that not converge, the QR is taken after all.
bool smallest_singular_values(const Matrix& J, double relative_threshold, double absolute_threshold,
                              SmallestSingularValues& out) {
  const Eigen::Index n = J.cols();
  if (J.rows() < n || n < 4) return false;
  {
    // Sparse, its few dense rows set apart (SparseGram): no QR at all.
    SparseGram sparse;
    std::vector<char> dense_row;
    if (sparse_view(J, sparse.a, dense_row) && sparse.factor_with_dense_rows(J, dense_row) &&
        smallest_singular_values(sparse, n, relative_threshold, absolute_threshold, out))
      return true;
  }
  const Eigen::HouseholderQR<Matrix> qr(J);
  TriangularGram triangular{qr.matrixQR().topRows(n).triangularView<Eigen::Upper>()};
  const double largest_pivot = triangular.r.diagonal().cwiseAbs().maxCoeff();
  if (!(largest_pivot > 0) || !std::isfinite(largest_pivot) ||
      !(triangular.r.diagonal().cwiseAbs().minCoeff() > 1e-15 * largest_pivot))
    return false;
  return smallest_singular_values(triangular, n, relative_threshold, absolute_threshold, out);
}

// The `count` leading singular values (descending) and right singular vectors of A by subspace
// iteration on A^T A with a block of count + 3 vectors (three steps from a fixed, deterministic
// start, then the Ritz values of A on the block): O(m n) per step where an SVD or eigensolver
// of A^T A is O(n^3) (1001 unknowns at 1000 intervals). The leading values wanted here stand
// 1e2..1e5 above the rest (a kink's rank-one jump), so three steps resolve them to far more
// than the 1e-2 they are compared at.
void leading_right_singular(const Matrix& A, Eigen::Index count, Vector& sigma, Matrix& right) {
  const Eigen::Index n = A.cols(), block = std::min<Eigen::Index>(n, count + 3);
  Matrix X(n, block);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < block; ++j)
      X(i, j) =
          std::cos(0.7 * static_cast<double>((i + 1) * (j + 1)) + 0.3 * static_cast<double>(j));
  for (int step = 0; step < 3; ++step) {
    const Matrix Y = A.transpose() * (A * X);
    const Eigen::HouseholderQR<Matrix> qr(Y);
    X = qr.householderQ() * Matrix::Identity(n, block);
  }
  const Eigen::JacobiSVD<Matrix> ritz(A * X, Eigen::ComputeThinV);
  const Eigen::Index kept = std::min<Eigen::Index>(count, ritz.singularValues().size());
  sigma = ritz.singularValues().head(kept);
  right = X * ritz.matrixV().leftCols(kept);
}

}  // namespace backbone::core
