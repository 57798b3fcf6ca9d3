// SUNDIALS KINSOL corrector (backend "kinsol"): inexact Newton with a dense direct linear
// solver and, optionally, KINSOL's line search (KIN_LINESEARCH, else KIN_NONE).
//
// Square systems only (m == n); a non-square problem returns
// NewtonStatus::linear_solver_failed with a message giving both sizes. The Jacobian comes from
// Problem::jacobian (analytic or finite differences, as the problem decides), so a KINSOL run
// and an Eigen run of the same problem differ only by the algorithm. KINSOL's own return-flag
// name is kept in NewtonSummary::message. Every SUNDIALS call of backbone lives in
// kinsol_newton.cpp; this header exposes none of them.
//
//   NewtonOptions opt; opt.residual_tolerance = 1e-12;
//   KinsolNewton newton(opt);
//   Vector x = guess;
//   NewtonSummary s = newton.solve(square_problem, x);
//   // s.message: "kinsol: KIN_SUCCESS after 5 iterations, ||F||_inf = 3.1e-15"
#pragma once

#include <string>

#include "core/solvers/newton.hpp"

namespace backbone::core {

class KinsolNewton : public Corrector {
 public:
  explicit KinsolNewton(const NewtonOptions& options);  // validates: throws InputError
  std::string name() const override { return "kinsol"; }
  using Corrector::solve;  // the nearby Jacobian is ignored: KINSOL forms its own
  NewtonSummary solve(const Problem& problem, Vector& x) override;
  const NewtonOptions& options() const { return options_; }

 private:
  NewtonOptions options_;
};

}  // namespace backbone::core
