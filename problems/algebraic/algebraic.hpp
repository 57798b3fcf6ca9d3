// Algebraic solution sets with known dimension and shape: test problems for continuation and
// for the rank report.
//
//   FoldCurve   x^2 + lambda - 1 = 0, unknowns [x, lambda]: a parabola with a fold at
//               (0, 1) in lambda (lambda rises, then falls along the curve). Dimension 1.
//   Circle      x^2 + y^2 - R^2 = 0 in R^2: a closed curve of length 2 pi R. Dimension 1.
//   Sphere      |x|^2 - R^2 = 0 in R^3: one equation, three unknowns. Dimension 2.
// Curves crossing other solution sets at exactly known branch points (tests of the branch-point
// detection, continuation/branch_points/branch_points.hpp):
//   Transcritical   x (lambda - 1 - x) = 0: the line x = 0 and the line x = lambda - 1 cross at
//                   (0, 1) at 45 degrees.
//   AxisAndCircle   x (x^2 + y^2 - 1) = 0: the y axis meets the unit circle at right angles at
//                   (0, -1) and (0, 1).
//   AxisAndPlane    [x (z - 1); y (z - 1)] = 0 in R^3: the z axis pierces the plane z = 1 at
//                   (0, 0, 1); the attached family is two-dimensional there.
//   Each takes `copies`: the residual repeated that many times (weights 1, 2, ...), a consistent
//   overdetermined system like the least-squares shooting residual (rank unchanged).
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
  std::string jacobian_description() const override { return "analytic"; }
  bool jacobian_exact() const override { return true; }
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
  std::string jacobian_description() const override { return "analytic"; }
  bool jacobian_exact() const override { return true; }

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

// Base of the branching test problems: `rows` equations repeated `copies` times (copy c
// weighted c + 1), so that copies > 1 is consistent and overdetermined.
class RepeatedRows : public core::Problem {
 public:
  RepeatedRows(int unknowns, int rows, int copies);  // InputError("copies") unless >= 1
  int num_unknowns() const override { return unknowns_; }
  int num_equations() const override { return rows_ * copies_; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override;
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override;
  std::string jacobian_description() const override { return "analytic"; }
  bool jacobian_exact() const override { return true; }
  // The `rows` equations and their Jacobian once.
  virtual void rows(const core::Vector& x, core::Vector& r) const = 0;
  virtual void rows_jacobian(const core::Vector& x, core::Matrix& J) const = 0;

 private:
  int unknowns_, rows_, copies_;
};

class Transcritical : public RepeatedRows {
 public:
  explicit Transcritical(int copies = 1) : RepeatedRows(2, 1, copies) {}
  std::string name() const override { return "transcritical"; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"x", x[0]}, {"lambda", x[1]}};
  }

 protected:
  void rows(const core::Vector& x, core::Vector& r) const override;
  void rows_jacobian(const core::Vector& x, core::Matrix& J) const override;
};

class AxisAndCircle : public RepeatedRows {
 public:
  explicit AxisAndCircle(int copies = 1) : RepeatedRows(2, 1, copies) {}
  std::string name() const override { return "axis_and_circle"; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"x", x[0]}, {"y", x[1]}};
  }

 protected:
  void rows(const core::Vector& x, core::Vector& r) const override;
  void rows_jacobian(const core::Vector& x, core::Matrix& J) const override;
};

class AxisAndPlane : public RepeatedRows {
 public:
  explicit AxisAndPlane(int copies = 1) : RepeatedRows(3, 2, copies) {}
  std::string name() const override { return "axis_and_plane"; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"x", x[0]}, {"y", x[1]}, {"z", x[2]}};
  }

 protected:
  void rows(const core::Vector& x, core::Vector& r) const override;
  void rows_jacobian(const core::Vector& x, core::Matrix& J) const override;
};

}  // namespace backbone::algebraic
