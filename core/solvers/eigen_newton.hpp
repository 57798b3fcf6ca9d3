// Dense Gauss-Newton corrector with Moore-Penrose minimum-norm steps (backend "eigen").
//
// Each iteration solves J dx = -F in the minimum-norm least-squares sense through a complete
// orthogonal decomposition of the m x n Jacobian, pivots below rank_cutoff * |R_11| being
// treated as zero. It therefore works unchanged for square, under-determined (m < n:
// the step is the shortest one onto the linearised solution set) and rank-deficient systems.
// With line_search, the step is halved until ||F||_2 decreases sufficiently (Armijo, c = 1e-4).
// Numerical failure is a status in the summary; bad options throw at construction.
//
//   NewtonOptions opt; opt.residual_tolerance = 1e-12;
//   EigenNewton newton(opt);
//   Vector x(2); x << 2.0, 0.1;                 // circle: 1 equation x^2 + y^2 - 1, 2 unknowns
//   NewtonSummary s = newton.solve(circle, x);  // minimum-norm steps are radial:
//   // x == (2, 0.1) / |(2, 0.1)|; s.residual_history shows quadratic convergence
#pragma once

#include <string>

#include "core/solvers/newton.hpp"

namespace backbone::core {

class EigenNewton : public Corrector {
 public:
  explicit EigenNewton(const NewtonOptions& options);  // validates: throws InputError
  std::string name() const override { return "eigen"; }
  NewtonSummary solve(const Problem& problem, Vector& x) override;
  // Chord steps on nearby_jacobian's factorization first (newton.hpp).
  NewtonSummary solve(const Problem& problem, Vector& x, const Matrix& nearby_jacobian) override;
  const NewtonOptions& options() const { return options_; }

 private:
  NewtonSummary solve_from(const Problem& problem, Vector& x, const Matrix* nearby_jacobian);
  NewtonOptions options_;
};

// The Moore-Penrose minimum-norm solution of J dx = rhs, singular values below
// rank_cutoff * sigma_max treated as zero. Returns the numerical rank used.
int minimum_norm_solve(const Matrix& J, const Vector& rhs, double rank_cutoff, Vector& dx);

}  // namespace backbone::core
