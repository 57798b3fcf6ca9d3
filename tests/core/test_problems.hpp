// Small algebraic problems with known roots and Jacobians, shared by the core tests.
//
//   backbone::core::testing::Rosenbrock rosenbrock;     // root (1, 1)
//   Vector x(2); x << -1.2, 1.0;
//   auto newton = make_corrector("eigen", NewtonOptions{});
//   EXPECT_TRUE(newton->solve(rosenbrock, x).converged());
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/problem.hpp"

namespace backbone::core::testing {

// Rosenbrock's system F = (10 (y - x^2), 1 - x): unique root (1, 1), analytic Jacobian.
class Rosenbrock : public Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 2; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r << 10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0];
    return EvalStatus::ok;
  }
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override {
    J << -20.0 * x[0], 10.0, -1.0, 0.0;
    return EvalStatus::ok;
  }
};

// Unit circle intersected with the line y = x: roots +-(1, 1)/sqrt(2). Jacobian by FD.
class CircleLine : public Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 2; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r << x.squaredNorm() - 1.0, x[1] - x[0];
    return EvalStatus::ok;
  }
};

// The unit sphere in R^dim (one equation): a regular manifold of dimension dim - 1.
class Sphere : public Problem {
 public:
  explicit Sphere(int dim) : dim_(dim) {}
  int num_unknowns() const override { return dim_; }
  int num_equations() const override { return 1; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r[0] = x.squaredNorm() - 1.0;
    return EvalStatus::ok;
  }
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override {
    J = 2.0 * x.transpose();
    return EvalStatus::ok;
  }

 private:
  int dim_;
};

// F(x, y) = (y - x^2)^2: the solution set is the parabola y = x^2 (a curve), but F touches
// zero quadratically, so the 1 x 2 Jacobian vanishes identically on it -- the algebraic twin
// of the paper's shooting residual on Duffing (core/README.md, section 'Shooting formulations').
class DoubleRootParabola : public Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    const double g = x[1] - x[0] * x[0];
    r[0] = g * g;
    return EvalStatus::ok;
  }
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override {
    const double g = x[1] - x[0] * x[0];
    J << -4.0 * x[0] * g, 2.0 * g;
    return EvalStatus::ok;
  }
};

// F(x, y) = max(x, 0)^2: the solution set is the half-plane x <= 0, a 2-manifold with the
// boundary x = 0 (as a continuum of periodic orbits ends at its grazing limits). On the
// boundary, solutions lie along -e_x only.
class HalfPlane : public Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    const double p = std::max(x[0], 0.0);
    r[0] = p * p;
    return EvalStatus::ok;
  }
};

// F = max(x, 0): the same half-plane x <= 0 as a zero set, but F has a kink on its boundary, so
// the forward-difference Jacobian at the origin is (1, 0) (nullity 1) while the family is 2D.
class KinkedHalfPlane : public Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r[0] = std::max(x[0], 0.0);
    return EvalStatus::ok;
  }
};

// A square system whose residual is NaN for x[0] > 0.5 (a "simulation that blew up").
class NanBeyondHalf : public Problem {
 public:
  int num_unknowns() const override { return 1; }
  int num_equations() const override { return 1; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r[0] = x[0] > 0.5 ? std::numeric_limits<double>::quiet_NaN() : x[0] - 0.25;
    return EvalStatus::ok;
  }
};

}  // namespace backbone::core::testing
