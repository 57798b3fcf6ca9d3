// Few singular values of a matrix, without its full SVD: the three solvers backbone uses.
//
// Each answers one question about a few singular values and vectors of a matrix whose full SVD
// would cost O(n^3) where the answer costs a few QRs or triangular solves:
//   - smallest_singular_triplet: the smallest singular value of a tall matrix with both its
//     singular vectors, from a start vector near the right one (the branch-point test function,
//     which follows the triplet from point to point): a Krylov basis of inverse iteration on the
//     matrix's triangular factor, and the Rayleigh-Ritz triplet on it;
//   - smallest_singular_values: the largest singular value and the smallest ones up to one above
//     a threshold, with their right vectors (the rank report at every point of a branch):
//     Lanczos bidiagonalisation for the largest, block inverse iteration with Rayleigh-Ritz steps
//     for the smallest, on the triangular factor or, for a sparse matrix, on a sparse Cholesky
//     factor of its normal matrix;
//   - leading_right_singular: the few largest singular values and right vectors of a matrix
//     whose leading values stand far above the rest (the directions along which a Jacobian
//     changed between two points): subspace iteration from a fixed start.
// They are three algorithms, not one with three settings: each caller's results are made of its
// own algorithm's bits, which the others' would change in the last digits. Each returns false
// where it cannot answer (the caller then takes a full SVD); none throws.
//
//   Vector u, v; double sigma;
//   if (!smallest_singular_triplet(A, previous_v, u, v, sigma)) { /* BDCSVD of A */ }
//   SmallestSingularValues few;
//   if (smallest_singular_values(J, 1e-8, 0.0, few)) use(few.largest, few.values, few.right);
//   Vector s; Matrix V;
//   leading_right_singular(D, 3, s, V);   // s descending, V n x 3
#pragma once

#include "core/types.hpp"

namespace backbone::core {

// The smallest singular triplet of the tall matrix A (rows >= cols): sigma, left (A v / sigma)
// and right (unit). From `start` (empty or zero: all ones), a Krylov basis of inverse iteration
// on R^T R (R: the triangular factor of A's Householder QR, with sigma(R) = sigma(A)), at most 40
// vectors, and the smallest singular triplet of R K on it, checked after 1, 2, 3, 4, 6, 9, ...
// vectors. Converged when |R^T u - sigma v| (a singular value of A lies within it of sigma) is
// below 1e-4 sigma + 1e-12 |A|_F. False when A is wide or empty, R has a zero pivot, the basis
// stops growing or does not converge within 40 vectors; left, right and sigma then mean nothing.
bool smallest_singular_triplet(const Matrix& A, const Vector& start, Vector& left, Vector& right,
                               double& sigma);

// What smallest_singular_values finds: sigma_max and the k smallest singular values (k = 8, 16,
// ...: one above the threshold at least), descending, with their right singular vectors.
struct SmallestSingularValues {
  double largest = 0;  // sigma_max (Lanczos estimate, to 1e-10 of itself)
  Vector values;       // the k smallest, descending
  Matrix right;        // n x k, orthonormal: their right singular vectors
};

// The smallest singular values of J (m >= n >= 4) up to one above the threshold
// max(relative_threshold * sigma_max, absolute_threshold), with their right vectors, and
// sigma_max. False when J is wide or smaller than 4 columns, R is singular to working
// precision, the block would exceed n / 2, or 60 steps do not converge.
bool smallest_singular_values(const Matrix& J, double relative_threshold, double absolute_threshold,
                              SmallestSingularValues& out);

// The `count` leading singular values of A (descending) and their right singular vectors
// (n x count), by three steps of subspace iteration on A^T A with a block of count + 3 vectors
// from a fixed start, then the Ritz values of A on the block. Accurate where the leading values
// stand well above the rest (1e2 and more: three steps then resolve them to 1e-6 and better).
void leading_right_singular(const Matrix& A, Eigen::Index count, Vector& sigma, Matrix& right);

}  // namespace backbone::core
