// Periodic orbits of a conservative mechanical system q'' = a(q), q in R^d, by shooting.
//
// A subclass gives the vector field (acceleration), the energy and, if it knows it, the
// stiffness da/dq; OdeOrbitProblem does the rest: the flow from rest by CVODE (Adams, see
// cvode_integrator.hpp), both shooting formulations of PeriodicOrbitProblem and an analytic
// Jacobian from the variational equations integrated alongside. Unknowns [q0 | T] (v0 = 0).
// Residuals (core/README.md, shooting formulations), made dimensionless by the orbit's own scale
// so that one Newton tolerance means the same relative accuracy at every amplitude:
//   half_period_velocity ("regular"):    v(T/2) / v_scale,  v_scale = sqrt(2 energy(x))
//   displacement_periodicity ("paper"):  (q0 - q(T)) / |q0|
// For unit mass and energy(x) = V(q0) measured from the potential minimum, v_scale is the largest
// speed on the orbit. The Jacobian includes the derivative of the scale, with
// d energy / d q0 = -a(q0) (a = -grad V); a subclass whose energy is not that potential
// overrides residual_scale.
//
//   class Pendulum : public core::OdeOrbitProblem {
//    public:
//     Pendulum() : OdeOrbitProblem(1) {}
//     void acceleration(const double* q, double* a) const override { a[0] = -std::sin(q[0]); }
//     double energy(const core::Vector& x) const override { return 1.0 - std::cos(x[0]); }
//   };
//   Pendulum p; core::Vector x(2); x << 0.5, 6.4;
//   core::Vector r; core::Matrix J;
//   p.residual(x, r); p.jacobian(x, J);          // 1 x 2, J analytic (variational equations)
#pragma once

#include <mutex>

#include "core/orbits/periodic_orbit.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::core {

struct OdeOrbitOptions {
  double relative_tolerance = 1e-13;  // CVODE rtol; absolute tolerances scale with the orbit
  long max_steps = 1000000;           // CVODE steps per flow
  void validate() const;              // InputError("rtol", ...), InputError("max_steps", ...)
};

// Divisor of the residual and its gradient with respect to q0.
struct ResidualScale {
  double value = 1;
  Vector gradient;  // d value / d q0, size d
};

// A conservative mechanical system q'' = a(q), q in R^d, as a periodic-orbit problem:
// unknowns [q0 | T] (v0 = 0), both shooting formulations of PeriodicOrbitProblem.
class OdeOrbitProblem : public PeriodicOrbitProblem, public FloquetProblem {
 public:
  static constexpr int max_dimension_keeping_jacobian = 2;
  explicit OdeOrbitProblem(int dimension, OdeOrbitOptions options = {});
  int state_size() const override;
  int num_parameters() const final { return 0; }  // unknowns are exactly [q0 | T]
  const OdeOrbitOptions& options() const { return options_; }

  // The vector field: a = q''(q). Must be safe to call concurrently.
  virtual void acceleration(const double* q, double* a) const = 0;
  // da/dq, d x d, column-major (Eigen default) into J (resized if needed). Default: central
  // differences of acceleration, step cbrt(eps) max(|q_j|, typical scale of q_j). Used by the
  // variational equations (analytic shooting Jacobian); must be safe to call concurrently.
  virtual void acceleration_jacobian(const double* q, Matrix& J) const;
  // energy(x) stays pure virtual (PeriodicOrbitProblem): the potential at q0. It must read
  // x.head(d) only (flow calls it with T = 0 for the velocity scale of the tolerances).

  // Flow from (q0, 0) over time t >= 0; with sensitivities (d x d each) when non-null, and the
  // derivative of the full state (q, v)(t) with respect to (q0, v0) (2d x 2d) when `full` is.
  // Returns false when CVODE fails (or t < 0); q0 must have d entries.
  bool flow(const Vector& q0, double t, Vector& q, Vector& v, Matrix* dq_dq0 = nullptr,
            Matrix* dv_dq0 = nullptr, Matrix* full = nullptr) const;

  // Divisor of the residual at x for the current formulation (see above), with its gradient.
  virtual ResidualScale residual_scale(const Vector& x) const;

  // Monodromy of the full state (q, v), 2d x 2d, from half a period: the system is reversible
  // (v -> -v, R = diag(I, -I)) and the orbit from rest is at rest again at T/2, so with
  // A = d(q, v)(T/2) / d(q0, v0), M = R A^-1 R A (core/README.md, section 'Stability'). For
  // d <= max_dimension_keeping_jacobian the last shot integrates A with the orbit and keeps M
  // (free after the residual that accepted x; the paper formulation's shot over T gives M
  // itself); else one flow of T/2 with the 2d x 2d variational equations.
  EvalStatus monodromy(const Vector& x, Matrix& M) const override;
  // Conservative: two multipliers at +1 (time shift and energy), M symplectic.
  FloquetStructure floquet_structure() const override { return {2, true}; }

 protected:
  // For d <= max_dimension_keeping_jacobian both integrate the variational equations alongside
  // the orbit (all 2d columns, for the monodromy) and keep the residual, the Jacobian and the
  // monodromy of the last point, so Newton's jacobian(x) after the residual(x) that accepted x,
  // a second residual(x) and monodromy(x) cost nothing: one flow per Newton iteration instead of
  // a flow and a flow with sensitivities (measured: 1.55x a flow at d = 1, 1.74x at d = 2, 3.9x
  // at d = 4, where a residual is a bare flow again).
  EvalStatus compute_residual(const Vector& x, Vector& r) const override;
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override;
  std::string jacobian_description() const override {
    return "analytic (the variational equations)";
  }
  // A subclass whose vector field or energy can change after construction (a parameter setter)
  // calls this when it does: the kept Jacobian belongs to the old field.
  void forget_last_shot() const;

 private:
  // Residual and analytic Jacobian at x from one flow with sensitivities; remembers J at x.
  EvalStatus shoot(const Vector& x, Vector& r, Matrix& J) const;
  // The monodromy from the shot's A (over T/2 for the regular formulation, T for the paper's).
  Matrix monodromy_from(const Matrix& A, ShootingFormulation formulation) const;
  // Speed scale of the orbit from rest at q0: sqrt(2 energy), floored away from zero.
  double velocity_scale(const Vector& q0) const;

  int dimension_;
  OdeOrbitOptions options_;
  // The last shot: J at x for that formulation (guarded: residuals may run concurrently).
  struct LastShot {
    Vector x;
    ShootingFormulation formulation = ShootingFormulation::half_period_velocity;
    Matrix jacobian;
    Vector residual;
    Matrix monodromy;  // empty when it was not finite
  };
  mutable std::mutex last_mutex_;
  mutable LastShot last_;
};

}  // namespace backbone::core
