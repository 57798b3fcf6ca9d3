// Algebraic solution sets with known dimension and shape: test problems for continuation and
// for the rank report.
//
//   FoldCurve   x^2 + lambda - 1 = 0, unknowns [x, lambda]: a parabola with a fold at
//               (0, 1) in lambda (lambda rises, then falls along the curve). Dimension 1.
//   Circle      x^2 + y^2 - R^2 = 0 in R^2: a closed curve of length 2 pi R. Dimension 1.
//   Sphere      |x|^2 - R^2 = 0 in R^3: one equation, three unknowns. Dimension 2.
// Analytic Jacobians; observables name the coordinates ("x", "lambda", "y", "z").
//
//   algebraic::FoldCurve fold;
//   core::Vector guess(2); guess << -1.5, -1.25;
//   core::Vector hint(2);  hint << 1.0, 0.0;           // x increases
//   auto b = continuation::pseudo_arclength(fold, guess, hint, *newton, opt);
//   // lambda goes up to 1 at x = 0, then down; x keeps increasing.
//   algebraic::Sphere sphere;  // rank_report(J) nullity 2, verified 2
#pragma once

#include "core/problem.hpp"

namespace backbone::algebraic {

class FoldCurve : public core::Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  std::string name() const override { return "fold_curve"; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"x", x[0]}, {"lambda", x[1]}};
  }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override;
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override;
};

// |x|^2 - radius^2 = 0 in R^dimension (dimension 2: circle, 3: sphere).
class QuadricSurface : public core::Problem {
 public:
  QuadricSurface(int ambient_dimension, double radius);  // InputError on bad sizes
  int num_unknowns() const override { return ambient_dimension_; }
  int num_equations() const override { return 1; }
  std::string name() const override { return ambient_dimension_ == 2 ? "circle" : "sphere"; }
  core::Observables observables(const core::Vector& x) const override;
  double radius() const { return radius_; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override;
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override;

 private:
  int ambient_dimension_;
  double radius_;
};

class Circle : public QuadricSurface {
 public:
  explicit Circle(double radius = 1.0) : QuadricSurface(2, radius) {}
};

class Sphere : public QuadricSurface {
 public:
  explicit Sphere(double radius = 1.0) : QuadricSurface(3, radius) {}
};

}  // namespace backbone::algebraic
