#include "core/orbits/ode_orbit.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "core/errors.hpp"
#include "core/orbits/cvode_integrator.hpp"

namespace backbone::core {

namespace {

// Scales are floored here so that a divisor or an absolute tolerance never becomes zero (an orbit
// at the equilibrium q0 = 0 has no scale of its own).
constexpr double smallest_scale = 1e-300;

double speed_of_energy(double energy) {
  return std::max(std::sqrt(std::max(2.0 * energy, 0.0)), smallest_scale);
}

}  // namespace

void OdeOrbitOptions::validate() const {
  if (!(relative_tolerance > 0 && relative_tolerance < 1e-3))
    throw InputError("rtol", fmt::format("must be in (0, 1e-3) (got {})", relative_tolerance));
  if (!(max_steps > 0))
    throw InputError("max_steps", fmt::format("must be > 0 (got {})", max_steps));
}

OdeOrbitProblem::OdeOrbitProblem(int dimension, OdeOrbitOptions options)
    : dimension_(dimension), options_(options) {
  if (dimension < 1) throw InputError("dimension", fmt::format("must be >= 1 (got {})", dimension));
  options_.validate();
}

int OdeOrbitProblem::state_size() const {
  return dimension_;
}

void OdeOrbitProblem::acceleration_jacobian(const double* q, Matrix& J) const {
  const int d = dimension_;
  J.resize(d, d);
  const Vector scale = typical_scale();
  const double relative_step = std::cbrt(std::numeric_limits<double>::epsilon());
  Vector shifted = Eigen::Map<const Vector>(q, d);
  Vector plus(d), minus(d);
  for (int j = 0; j < d; ++j) {
    const double typical = std::abs(scale[j]) > 0 ? std::abs(scale[j]) : 1.0;
    const double h0 = relative_step * std::max(std::abs(q[j]), typical);
    // Round the step so that q_j + h is exactly representable (same rule as
    // finite_difference.hpp).
    volatile double moved = q[j] + h0;
    const double h = moved - q[j];
    shifted[j] = q[j] + h;
    acceleration(shifted.data(), plus.data());
    shifted[j] = q[j] - h;
    acceleration(shifted.data(), minus.data());
    shifted[j] = q[j];
    J.col(j) = (plus - minus) / (2.0 * h);
  }
}

double OdeOrbitProblem::velocity_scale(const Vector& q0) const {
  Vector x = Vector::Zero(num_unknowns());
  x.head(dimension_) = q0;
  return speed_of_energy(energy(x));
}

bool OdeOrbitProblem::flow(const Vector& q0, double t, Vector& q, Vector& v, Matrix* dq_dq0,
                           Matrix* dv_dq0, Matrix* full) const {
  const int d = dimension_;
  if (q0.size() != d)
    throw std::invalid_argument(
        fmt::format("OdeOrbitProblem::flow: q0 has {} entries for dimension {}", q0.size(), d));
  if (t == 0) {
    q = q0;
    v = Vector::Zero(d);
    if (dq_dq0) *dq_dq0 = Matrix::Identity(d, d);
    if (dv_dq0) *dv_dq0 = Matrix::Zero(d, d);
    if (full) *full = Matrix::Identity(2 * d, 2 * d);
    return true;
  }
  if (!(t > 0) || !std::isfinite(t)) return false;
  // Columns of the variational state: none, those of q0, or those of (q0, v0).
  const int k = full ? 2 * d : (dq_dq0 != nullptr || dv_dq0 != nullptr ? d : 0);

  // State y = [q | v | Q | V], Q = dq/d(start) and V = dv/d(start) d x k, column-major, starting
  // at Q = [I 0], V = [0 I]. Absolute tolerances a factor 1e-3 below rtol times each
  // component's scale on the orbit (amplitude, speed, 1 and the frequency sqrt(|da/dq|)), so
  // that the relative tolerance governs even near zero crossings. The variational components
  // take part in the error test: left out (CVODES' default for sensitivities), they drift where
  // they grow fast, and the measured pendulum backbone (tests/outside_problem) then stalls near
  // the separatrix on a poor Jacobian.
  const int size = 2 * d + 2 * d * k;
  const double floor = 1e-3 * options_.relative_tolerance;
  const double amplitude = std::max(q0.norm(), smallest_scale);
  CvodeOptions cvode;
  cvode.relative_tolerance = options_.relative_tolerance;
  cvode.max_steps = options_.max_steps;
  cvode.absolute_tolerance.resize(size);
  cvode.absolute_tolerance.head(d).setConstant(floor * amplitude);
  cvode.absolute_tolerance.segment(d, d).setConstant(floor * velocity_scale(q0));
  Vector y = Vector::Zero(size);
  y.head(d) = q0;
  if (k > 0) {
    Matrix stiffness_matrix(d, d);
    acceleration_jacobian(q0.data(), stiffness_matrix);
    const double stiffness =
        std::max(stiffness_matrix.cwiseAbs().rowwise().sum().maxCoeff(), smallest_scale);
    Eigen::Map<Matrix>(y.data() + 2 * d, d, k).leftCols(d).setIdentity();
    if (k == 2 * d) Eigen::Map<Matrix>(y.data() + 2 * d + d * k, d, k).rightCols(d).setIdentity();
    cvode.absolute_tolerance.segment(2 * d, d * k).setConstant(floor);
    cvode.absolute_tolerance.tail(d * k).setConstant(floor * std::sqrt(stiffness));
  }

  // The workspace lives in this call's copy of the lambda: concurrent flows share nothing.
  const OdeRightHandSide rhs = [this, d, k, stiffness = Matrix(d, d)](double, const double* s,
                                                                      double* ds) mutable {
    for (int i = 0; i < d; ++i) ds[i] = s[d + i];
    acceleration(s, ds + d);
    if (k == 0) return;
    acceleration_jacobian(s, stiffness);
    const Eigen::Map<const Matrix> dq(s + 2 * d, d, k);
    const Eigen::Map<const Matrix> dv(s + 2 * d + d * k, d, k);
    Eigen::Map<Matrix>(ds + 2 * d, d, k) = dv;
    Eigen::Map<Matrix>(ds + 2 * d + d * k, d, k).noalias() = stiffness * dq;
  };
  const IntegrationResult result = integrate_ode(rhs, y, t, cvode);
  if (!result.ok) return false;
  q = y.head(d);
  v = y.segment(d, d);
  if (k == 0) return true;
  const Eigen::Map<const Matrix> Q(y.data() + 2 * d, d, k), V(y.data() + 2 * d + d * k, d, k);
  if (dq_dq0) *dq_dq0 = Q.leftCols(d);
  if (dv_dq0) *dv_dq0 = V.leftCols(d);
  if (full) {
    full->resize(2 * d, 2 * d);
    full->topRows(d) = Q;
    full->bottomRows(d) = V;
  }
  return true;
}

ResidualScale OdeOrbitProblem::residual_scale(const Vector& x) const {
  const int d = dimension_;
  const Vector q0 = x.head(d);
  ResidualScale scale;
  if (formulation() == ShootingFormulation::half_period_velocity) {
    // v_scale = sqrt(2 E(q0)): d v_scale / d q0 = grad E / v_scale = -a(q0) / v_scale.
    scale.value = speed_of_energy(energy(x));
    Vector a(d);
    acceleration(q0.data(), a.data());
    scale.gradient = -a / scale.value;
  } else {
    scale.value = std::max(q0.norm(), smallest_scale);
    scale.gradient = q0 / scale.value;
  }
  return scale;
}

EvalStatus OdeOrbitProblem::shoot(const Vector& x, Vector& r, Matrix& J) const {
  const int d = dimension_;
  const double period = x[period_index()];
  if (!(period > 0) || !x.head(d).allFinite()) return EvalStatus::failed;
  const Vector q0 = x.head(d);
  Vector q, v, raw;
  Matrix dq_dq0, dv_dq0, A;
  J.resize(d, d + 1);
  if (formulation() == ShootingFormulation::half_period_velocity) {
    // r = v(T/2): dr/dq0 = dv/dq0 (T/2), dr/dT = a(q(T/2)) / 2.
    if (!flow(q0, 0.5 * period, q, v, &dq_dq0, &dv_dq0, &A)) return EvalStatus::failed;
    Vector a(d);
    acceleration(q.data(), a.data());
    J.leftCols(d) = dv_dq0;
    J.col(d) = 0.5 * a;
    raw = v;
  } else {
    // r = q0 - q(T): dr/dq0 = I - dq/dq0 (T), dr/dT = -v(T).
    if (!flow(q0, period, q, v, &dq_dq0, &dv_dq0, &A)) return EvalStatus::failed;
    J.leftCols(d) = Matrix::Identity(d, d) - dq_dq0;
    J.col(d) = -v;
    raw = q0 - q;
  }
  // d(raw / s)/dq0 = raw'/s - raw s'^T / s^2 (product rule; the second term vanishes on orbits).
  const ResidualScale scale = residual_scale(x);
  r = raw / scale.value;
  J /= scale.value;
  const double s2 = scale.value * scale.value;
  for (int j = 0; j < d; ++j)
    for (int i = 0; i < d; ++i) J(i, j) -= raw[i] * scale.gradient[j] / s2;
  const Matrix M = monodromy_from(A, formulation());
  const std::lock_guard<std::mutex> lock(last_mutex_);
  last_.x = x;
  last_.formulation = formulation();
  last_.jacobian = J;
  last_.residual = r;
  last_.monodromy = M.allFinite() ? M : Matrix();
  return EvalStatus::ok;
}

Matrix OdeOrbitProblem::monodromy_from(const Matrix& A, ShootingFormulation formulation) const {
  if (formulation == ShootingFormulation::displacement_periodicity) return A;  // A = d y(T) / d y0
  // Reversibility (the header): M = R A^-1 R A with A over half the period.
  const int d = dimension_;
  Vector R = Vector::Ones(2 * d);
  R.tail(d).setConstant(-1);
  Eigen::PartialPivLU<Matrix> lu(A);
  return R.asDiagonal() * lu.solve(Matrix(R.asDiagonal() * A));
}

EvalStatus OdeOrbitProblem::monodromy(const Vector& x, Matrix& M) const {
  {
    const std::lock_guard<std::mutex> lock(last_mutex_);
    if (last_.x.size() == x.size() && last_.x == x && last_.monodromy.size() > 0) {
      M = last_.monodromy;
      return EvalStatus::ok;
    }
  }
  const int d = dimension_;
  const double period = x[period_index()];
  if (!(period > 0) || !std::isfinite(period) || !x.head(d).allFinite()) return EvalStatus::failed;
  Vector q, v;
  Matrix A;
  if (!flow(x.head(d), 0.5 * period, q, v, nullptr, nullptr, &A)) return EvalStatus::failed;
  M = monodromy_from(A, ShootingFormulation::half_period_velocity);
  return M.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
}

void OdeOrbitProblem::forget_last_shot() const {
  const std::lock_guard<std::mutex> lock(last_mutex_);
  last_.x.resize(0);
}

EvalStatus OdeOrbitProblem::compute_residual(const Vector& x, Vector& r) const {
  // Measured (a nonlinear chain, 3 time units): a flow with sensitivities costs 1.55x one
  // without at d = 1, 1.74x at d = 2, 3.9x at d = 4 and 7x at d = 8 (the variational state has
  // 2d^2 components). Up to d = 2 every residual carries them (one flow per Newton iteration);
  // beyond, a residual is a bare flow and the Jacobian its own.
  if (dimension_ <= max_dimension_keeping_jacobian) {
    {
      const std::lock_guard<std::mutex> lock(last_mutex_);
      if (last_.formulation == formulation() && last_.x.size() == x.size() && last_.x == x) {
        r = last_.residual;
        return EvalStatus::ok;
      }
    }
    Matrix J;
    return shoot(x, r, J);
  }
  const int d = dimension_;
  const double period = x[period_index()];
  if (!(period > 0) || !x.head(d).allFinite()) return EvalStatus::failed;
  const Vector q0 = x.head(d);
  Vector q, v;
  const ResidualScale scale = residual_scale(x);
  if (formulation() == ShootingFormulation::half_period_velocity) {
    if (!flow(q0, 0.5 * period, q, v)) return EvalStatus::failed;
    r = v / scale.value;
  } else {
    if (!flow(q0, period, q, v)) return EvalStatus::failed;
    r = (q0 - q) / scale.value;
  }
  return EvalStatus::ok;
}

EvalStatus OdeOrbitProblem::compute_jacobian(const Vector& x, Matrix& J) const {
  {
    const std::lock_guard<std::mutex> lock(last_mutex_);
    if (last_.formulation == formulation() && last_.x.size() == x.size() && last_.x == x) {
      J = last_.jacobian;
      return EvalStatus::ok;
    }
  }
  Vector r;
  return shoot(x, r, J);
}

}  // namespace backbone::core
