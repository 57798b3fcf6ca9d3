// The generic ODE shooting wrapper (core/orbits/ode_orbit.hpp) against exact oracles: the harmonic
// oscillator (T = 2 pi at every amplitude, closed-form flow and Jacobian), a linear two-mass
// chain (normal modes with periods 2 pi and 2 pi / sqrt(3), closed-form Jacobian off the orbit)
// and a coupled nonlinear system (Jacobian against finite differences); the Jacobian kept from
// the last shot and the re-used CVODE memory against fresh computations.
//
// Tolerances: CVODE runs at rtol 1e-13 with absolute tolerances 1e-3 below it; over the few
// radians integrated here the global error stays below ~1e-12 of the orbit's scale, so values
// and derivatives of size 1 are checked to 1e-10 (a margin of ~100).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>

#include "core/errors.hpp"
#include "core/jacobians/jacobian_check.hpp"
#include "core/orbits/cvode_integrator.hpp"
#include "core/orbits/ode_orbit.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::core {
namespace {

constexpr double pi = std::numbers::pi;
constexpr double close = 1e-10;  // see the header note

Vector vec(std::initializer_list<double> values) {
  Vector v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double value : values) v[i++] = value;
  return v;
}

// q'' = -q, V = q^2 / 2. The stiffness comes from the default (finite differences): exact up to
// round-off for a linear field.
class HarmonicOscillator : public OdeOrbitProblem {
 public:
  explicit HarmonicOscillator(OdeOrbitOptions options = {}) : OdeOrbitProblem(1, options) {}
  void acceleration(const double* q, double* a) const override { a[0] = -q[0]; }
  double energy(const Vector& x) const override { return 0.5 * x[0] * x[0]; }
};

// Two unit masses, three unit springs (wall-mass-mass-wall): q'' = -K q, K = [2 -1; -1 2].
// Normal modes (1, 1) / sqrt 2 with omega = 1 and (1, -1) / sqrt 2 with omega = sqrt 3.
class LinearChain : public OdeOrbitProblem {
 public:
  LinearChain() : OdeOrbitProblem(2) {}
  static Matrix stiffness() { return (Matrix(2, 2) << 2.0, -1.0, -1.0, 2.0).finished(); }
  void acceleration(const double* q, double* a) const override {
    a[0] = -2.0 * q[0] + q[1];
    a[1] = q[0] - 2.0 * q[1];
  }
  void acceleration_jacobian(const double*, Matrix& J) const override { J = -stiffness(); }
  double energy(const Vector& x) const override {
    const Vector q = x.head(2);
    return 0.5 * q.dot(stiffness() * q);
  }
};

// Closed forms of the chain: K = P diag(omega^2) P^T, so q(t) = C(t) q0, v(t) = -S(t) q0 with
// C = P cos(omega t) P^T and S = P omega sin(omega t) P^T.
struct ChainFlow {
  Matrix C, S;
  explicit ChainFlow(double t) {
    const Matrix P = (Matrix(2, 2) << 1.0, 1.0, 1.0, -1.0).finished() / std::sqrt(2.0);
    const Vector omega = vec({1.0, std::sqrt(3.0)});
    C = P * (omega * t).array().cos().matrix().asDiagonal() * P.transpose();
    S = P * (omega.array() * (omega * t).array().sin()).matrix().asDiagonal() * P.transpose();
  }
};

// V = q1^2 / 2 + q2^2 + (q1 - q2)^4 / 4, a = -grad V: two unequal oscillators coupled by a
// quartic spring. analytic = false leaves the stiffness to the default finite differences.
class CoupledQuartic : public OdeOrbitProblem {
 public:
  explicit CoupledQuartic(bool analytic) : OdeOrbitProblem(2), analytic_(analytic) {}
  void acceleration(const double* q, double* a) const override {
    const double d = q[0] - q[1];
    a[0] = -q[0] - d * d * d;
    a[1] = -2.0 * q[1] + d * d * d;
  }
  void acceleration_jacobian(const double* q, Matrix& J) const override {
    if (!analytic_) return OdeOrbitProblem::acceleration_jacobian(q, J);
    const double c = 3.0 * (q[0] - q[1]) * (q[0] - q[1]);
    J.resize(2, 2);
    J << -1.0 - c, c, c, -2.0 - c;
  }
  double energy(const Vector& x) const override {
    const double d = x[0] - x[1];
    return 0.5 * x[0] * x[0] + x[1] * x[1] + 0.25 * d * d * d * d;
  }

 private:
  bool analytic_;
};

// A field with a non-symmetric Jacobian, to pin the column-major layout of the default
// acceleration_jacobian: a = (q2^2, q1 q2 + 3 q1), da/dq = [0, 2 q2; q2 + 3, q1].
class Skewed : public OdeOrbitProblem {
 public:
  Skewed() : OdeOrbitProblem(2) {}
  void acceleration(const double* q, double* a) const override {
    a[0] = q[1] * q[1];
    a[1] = q[0] * q[1] + 3.0 * q[0];
  }
  double energy(const Vector&) const override { return 0; }
};

TEST(OdeOrbit, HarmonicFlowAndSensitivitiesAreExact) {
  HarmonicOscillator h;
  for (double amplitude : {2.0, -0.5}) {
    Vector q, v;
    Matrix dq, dv;
    const double t = 1.3;
    ASSERT_TRUE(h.flow(vec({amplitude}), t, q, v, &dq, &dv));
    EXPECT_NEAR(q[0], amplitude * std::cos(t), close * std::abs(amplitude));
    EXPECT_NEAR(v[0], -amplitude * std::sin(t), close * std::abs(amplitude));
    EXPECT_NEAR(dq(0, 0), std::cos(t), close);
    EXPECT_NEAR(dv(0, 0), -std::sin(t), close);
  }
  Vector q, v;
  Matrix dq;
  ASSERT_TRUE(h.flow(vec({0.3}), 0.0, q, v, &dq));  // t = 0: the identity, no integration
  EXPECT_EQ(q[0], 0.3);
  EXPECT_EQ(v[0], 0.0);
  EXPECT_EQ(dq(0, 0), 1.0);
  EXPECT_FALSE(h.flow(vec({0.3}), -1.0, q, v));
}

// Regular formulation: Newton from a period 10% off lands on T = 2 pi at every amplitude. The
// scaled residual is -sign(q0) sin(T/2), so dr/dT = 1/2 at the root and |T - 2 pi| ~ 2 |r|:
// Newton's 1e-12 plus the integration error give ~1e-11; 1e-10 is the bound.
TEST(OdeOrbit, HarmonicPeriodIsTwoPiAtEveryAmplitude) {
  HarmonicOscillator h;
  NewtonOptions options;
  options.residual_tolerance = 1e-12;
  auto newton = make_corrector("eigen", options);  // minimum-norm steps: 1 equation, 2 unknowns
  double worst = 0;
  for (double amplitude : {1e-3, 1.0, 1e3}) {
    Vector x = vec({amplitude, 1.1 * 2 * pi});
    const NewtonSummary s = newton->solve(h, x);
    ASSERT_TRUE(s.converged()) << "A = " << amplitude << ": " << s.message;
    EXPECT_NEAR(x[1], 2 * pi, close) << "A = " << amplitude;
    // dr/dq0 = 0 exactly, so the minimum-norm step leaves the amplitude alone.
    EXPECT_NEAR(x[0], amplitude, 1e-9 * amplitude);
    worst = std::max(worst, std::abs(x[1] - 2 * pi));
  }
  std::cout << "[ measured ] worst |T - 2 pi| = " << worst << "\n";
  // Paper formulation: the residual vanishes at T = 2 pi too (a double root, so no Newton).
  h.set_formulation(ShootingFormulation::displacement_periodicity);
  for (double amplitude : {1e-3, 1.0, 1e3}) {
    Vector r;
    ASSERT_EQ(h.residual(vec({amplitude, 2 * pi}), r), EvalStatus::ok);
    EXPECT_LE(std::abs(r[0]), close) << "A = " << amplitude;
  }
}

// Off the orbit (T = 5) the scaled residuals and Jacobians are closed forms:
//   regular r = v(T/2) / |q0| = -sign(q0) sin(T/2),     J = [0, -sign(q0) cos(T/2) / 2]
//   paper   r = (q0 - q(T)) / |q0| = sign(q0)(1 - cos T), J = [0, sign(q0) sin T]
// J(0, 0) = 0 only because the derivative of the scale cancels dv/dq0 / s: it checks that term.
TEST(OdeOrbit, HarmonicResidualAndJacobianOffTheOrbit) {
  HarmonicOscillator h;
  const double T = 5.0;
  for (double amplitude : {2.0, -0.7}) {
    const double sign = amplitude > 0 ? 1.0 : -1.0;
    const Vector x = vec({amplitude, T});
    Vector r;
    Matrix J;
    h.set_formulation(ShootingFormulation::half_period_velocity);
    ASSERT_EQ(h.residual(x, r), EvalStatus::ok);
    ASSERT_EQ(h.jacobian(x, J), EvalStatus::ok);
    EXPECT_NEAR(r[0], -sign * std::sin(T / 2), close);
    EXPECT_NEAR(J(0, 0), 0.0, close);
    EXPECT_NEAR(J(0, 1), -sign * std::cos(T / 2) / 2, close);
    h.set_formulation(ShootingFormulation::displacement_periodicity);
    ASSERT_EQ(h.residual(x, r), EvalStatus::ok);
    ASSERT_EQ(h.jacobian(x, J), EvalStatus::ok);
    EXPECT_NEAR(r[0], sign * (1 - std::cos(T)), close);
    EXPECT_NEAR(J(0, 0), 0.0, close);
    EXPECT_NEAR(J(0, 1), sign * std::sin(T), close);
  }
}

// Each normal mode of the chain is periodic with its own period; swapping the periods gives an
// O(1) residual (the check can fail).
TEST(OdeOrbit, LinearChainNormalModesHaveTheirPeriods) {
  LinearChain chain;
  const Vector in_phase = vec({0.8, 0.8}), anti_phase = vec({0.8, -0.8});
  const double T1 = 2 * pi, T2 = 2 * pi / std::sqrt(3.0);
  for (auto f :
       {ShootingFormulation::half_period_velocity, ShootingFormulation::displacement_periodicity}) {
    chain.set_formulation(f);
    Vector r;
    ASSERT_EQ(chain.residual(vec({0.8, 0.8, T1}), r), EvalStatus::ok);
    EXPECT_LE(r.cwiseAbs().maxCoeff(), close) << to_string(f);
    ASSERT_EQ(chain.residual(vec({0.8, -0.8, T2}), r), EvalStatus::ok);
    EXPECT_LE(r.cwiseAbs().maxCoeff(), close) << to_string(f);
    ASSERT_EQ(chain.residual(vec({0.8, 0.8, T2}), r), EvalStatus::ok);
    EXPECT_GE(r.cwiseAbs().maxCoeff(), 0.1) << to_string(f);
  }
  // Regular: the Jacobian on the in-phase mode annihilates the mode direction (the family at
  // fixed T) and nothing else: nullity exactly 1 of the 2 x 3 matrix.
  chain.set_formulation(ShootingFormulation::half_period_velocity);
  Matrix J;
  ASSERT_EQ(chain.jacobian(vec({0.8, 0.8, T1}), J), EvalStatus::ok);
  EXPECT_LE((J * vec({1.0, 1.0, 0.0})).cwiseAbs().maxCoeff(), close) << J;
  const Eigen::JacobiSVD<Matrix> svd(J);
  EXPECT_GE(svd.singularValues().minCoeff(), 0.1) << J;
}

// Full 2 x 3 Jacobians of the chain off the orbit, against the closed forms of ChainFlow with
// the scale derivatives written out:
//   regular: s = sqrt(2 E) = sqrt(q0' K q0), grad s = K q0 / s, r = -S(T/2) q0 / s,
//            J_q = -S / s - (-S q0)(K q0)' / s^3,   J_T = -K C(T/2) q0 / (2 s)
//   paper:   s = |q0|, r = (I - C(T)) q0 / s,
//            J_q = (I - C) / s - (I - C) q0 q0' / s^3,   J_T = S(T) q0 / s
TEST(OdeOrbit, LinearChainJacobianMatchesClosedForm) {
  LinearChain chain;
  const Vector q0 = vec({0.7, -0.2});
  const double T = 4.1;
  const Vector x = vec({q0[0], q0[1], T});
  const Matrix K = LinearChain::stiffness();
  const Matrix I = Matrix::Identity(2, 2);
  Matrix expected(2, 3), J;
  Vector r;

  const ChainFlow half(T / 2);
  const double s = std::sqrt(q0.dot(K * q0));
  const Vector v = -half.S * q0;
  expected.leftCols(2) = -half.S / s - v * (K * q0).transpose() / (s * s * s);
  expected.col(2) = -K * half.C * q0 / (2 * s);
  ASSERT_EQ(chain.residual(x, r), EvalStatus::ok);
  ASSERT_EQ(chain.jacobian(x, J), EvalStatus::ok);
  EXPECT_LE((r - v / s).cwiseAbs().maxCoeff(), close);
  EXPECT_LE((J - expected).cwiseAbs().maxCoeff(), close) << J << "\nvs\n" << expected;

  chain.set_formulation(ShootingFormulation::displacement_periodicity);
  const ChainFlow full(T);
  const double n = q0.norm();
  const Vector raw = (I - full.C) * q0;
  expected.leftCols(2) = (I - full.C) / n - raw * q0.transpose() / (n * n * n);
  expected.col(2) = full.S * q0 / n;
  ASSERT_EQ(chain.residual(x, r), EvalStatus::ok);
  ASSERT_EQ(chain.jacobian(x, J), EvalStatus::ok);
  EXPECT_LE((r - raw / n).cwiseAbs().maxCoeff(), close);
  EXPECT_LE((J - expected).cwiseAbs().maxCoeff(), close) << J << "\nvs\n" << expected;
}

// Nonlinear, coupled: the variational Jacobian against central finite differences of the
// residual. The FD error is dominated by integration noise, not truncation: CVODE's adaptive
// steps change with the perturbed start, so the residual carries ~1e-12 of noise, divided by the
// step cbrt(eps) ~ 6e-6: ~2e-7 (measured 1e-7, and it does not shrink with the step). A wrong
// layout or a missing scale derivative is O(1); 1e-6 sits between.
TEST(OdeOrbit, CoupledNonlinearJacobianMatchesFiniteDifferences) {
  const Vector x = vec({0.9, -0.4, 5.3});  // off any orbit: every term of J counts
  for (bool analytic : {true, false}) {
    CoupledQuartic problem(analytic);
    // dq/dq0 is not symmetric here, so a transposed sensitivity block would be caught.
    Vector q, v;
    Matrix dq;
    ASSERT_TRUE(problem.flow(x.head(2), x[2], q, v, &dq));
    ASSERT_GE(std::abs(dq(0, 1) - dq(1, 0)), 1e-2) << dq;
    for (auto f : {ShootingFormulation::half_period_velocity,
                   ShootingFormulation::displacement_periodicity}) {
      problem.set_formulation(f);
      const JacobianCheck check = check_jacobian(problem, x, /*threads=*/2);
      ASSERT_EQ(check.status, EvalStatus::ok);
      EXPECT_LE(check.central.max_relative_error, 1e-6)
          << to_string(f) << (analytic ? " analytic" : " fd") << ": " << check.summary();
      std::cout << "[ measured ] " << to_string(f) << (analytic ? ", analytic" : ", fd")
                << " stiffness: " << check.summary() << "\n";
    }
  }
}

// The default stiffness is central differences in column-major layout: exact up to round-off
// (~eps / cbrt(eps) ~ 4e-11) for this quadratic field.
TEST(OdeOrbit, DefaultAccelerationJacobianIsColumnMajor) {
  Skewed field;
  const double q[2] = {0.3, -1.2};
  Matrix J;
  field.acceleration_jacobian(q, J);
  ASSERT_EQ(J.rows(), 2);
  ASSERT_EQ(J.cols(), 2);
  Matrix exact(2, 2);
  exact << 0.0, 2 * q[1], q[1] + 3.0, q[0];
  EXPECT_LE((J - exact).cwiseAbs().maxCoeff(), 1e-9) << J;
}

// The Jacobian kept from the last shot (ode_orbit.hpp) is the one a fresh shot computes, bit for
// bit, and only at that point and formulation: a stale one (wrong x, or the other formulation)
// differs in O(1) entries off the orbit, so every EXPECT_EQ here can fail.
TEST(OdeOrbit, KeptJacobianIsTheFreshOneAtThatPointOnly) {
  const Vector x1 = vec({0.9, -0.4, 5.3}), x2 = vec({0.5, 0.1, 4.0});
  const auto fresh_jacobian = [](const Vector& x, ShootingFormulation f) {
    CoupledQuartic problem(true);
    problem.set_formulation(f);
    Matrix J;
    EXPECT_EQ(problem.jacobian(x, J), EvalStatus::ok);
    return J;
  };
  CoupledQuartic problem(true);
  Vector r;
  Matrix J;
  ASSERT_EQ(problem.residual(x1, r), EvalStatus::ok);
  ASSERT_EQ(problem.jacobian(x1, J), EvalStatus::ok);
  EXPECT_EQ(J, fresh_jacobian(x1, ShootingFormulation::half_period_velocity));
  ASSERT_EQ(problem.residual(x2, r), EvalStatus::ok);
  ASSERT_EQ(problem.jacobian(x1, J), EvalStatus::ok);  // not the kept one (x2)
  EXPECT_EQ(J, fresh_jacobian(x1, ShootingFormulation::half_period_velocity));
  problem.set_formulation(ShootingFormulation::displacement_periodicity);
  ASSERT_EQ(problem.jacobian(x1, J), EvalStatus::ok);  // same x, other formulation
  EXPECT_EQ(J, fresh_jacobian(x1, ShootingFormulation::displacement_periodicity));
  EXPECT_GE(
      (J - fresh_jacobian(x1, ShootingFormulation::half_period_velocity)).cwiseAbs().maxCoeff(),
      1e-2);  // the two formulations' Jacobians differ: the check above can fail
}

// integrate_ode re-initialises one CVODE memory per thread: a call after calls of other sizes
// and tolerances repeats the first one bit for bit, and matches the harmonic closed form.
TEST(CvodeIntegrator, ReusedMemoryRepeatsTheFirstIntegrationExactly) {
  const OdeRightHandSide harmonic = [](double, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = -y[0];
  };
  const OdeRightHandSide decay = [](double, const double* y, double* dy) {
    for (int i = 0; i < 3; ++i) dy[i] = -y[i];
  };
  CvodeOptions options;
  options.relative_tolerance = 1e-12;
  const auto run = [&](const OdeRightHandSide& f, Vector y, double t, const CvodeOptions& o) {
    const IntegrationResult result = integrate_ode(f, y, t, o);
    EXPECT_TRUE(result.ok) << result.message;
    return y;
  };
  const Vector first = run(harmonic, vec({1.0, 0.0}), 2.0, options);
  CvodeOptions loose;
  loose.relative_tolerance = 1e-6;
  run(decay, vec({1.0, 2.0, 3.0}), 5.0, loose);  // another size: the memory is rebuilt
  run(harmonic, vec({0.3, 0.1}), 7.0, loose);    // same size, other start and tolerance
  const Vector again = run(harmonic, vec({1.0, 0.0}), 2.0, options);
  EXPECT_EQ(again, first);
  // Global error at rtol 1e-12 over 2 radians: ~1e-11 (see the header note: 1e-10).
  EXPECT_NEAR(first[0], std::cos(2.0), close);
  EXPECT_NEAR(first[1], -std::sin(2.0), close);
}

TEST(OdeOrbit, BadOptionsAreInputErrors) {
  const auto key_of = [](OdeOrbitOptions options, int dimension = 1) {
    try {
      struct Probe : OdeOrbitProblem {
        Probe(int d, OdeOrbitOptions o) : OdeOrbitProblem(d, o) {}
        void acceleration(const double*, double*) const override {}
        double energy(const Vector&) const override { return 0; }
      } probe(dimension, options);
    } catch (const InputError& e) {
      return e.key();
    }
    return std::string("none");
  };
  EXPECT_EQ(key_of({}), "none");
  EXPECT_EQ(key_of({0.0}), "rtol");
  EXPECT_EQ(key_of({1e-2}), "rtol");
  EXPECT_EQ(key_of({std::nan("")}), "rtol");
  EXPECT_EQ(key_of({1e-10, 0}), "max_steps");
  EXPECT_EQ(key_of({}, 0), "dimension");
}

TEST(OdeOrbit, NumericalFailuresAreStatusValues) {
  HarmonicOscillator h;
  Vector r;
  EXPECT_EQ(h.residual(vec({1.0, 0.0}), r), EvalStatus::failed);
  EXPECT_EQ(h.residual(vec({1.0, -1.0}), r), EvalStatus::failed);
  EXPECT_EQ(h.residual(vec({std::nan(""), 6.0}), r), EvalStatus::failed);
  OdeOrbitOptions few_steps;
  few_steps.max_steps = 5;  // ~30 Adams steps per radian at rtol 1e-13: 100 radians need more
  HarmonicOscillator starved(few_steps);
  EXPECT_EQ(starved.residual(vec({1.0, 200.0}), r), EvalStatus::failed);
  Matrix J;
  EXPECT_EQ(starved.jacobian(vec({1.0, 200.0}), J), EvalStatus::failed);
}

}  // namespace
}  // namespace backbone::core
