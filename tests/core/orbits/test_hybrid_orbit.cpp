// HybridOrbitProblem against systems whose periodic orbits and multipliers are known exactly: a
// damped forced linear oscillator (forced, no events), the Hopf normal form (autonomous), and a
// forced oscillator whose orbit pokes through a switching surface for a time far shorter than a
// CVODE step (an event that must not be lost). Bad guesses are refused with the key they break.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include "core/errors.hpp"
#include "core/orbits/hybrid_orbit.hpp"

namespace core = backbone::core;

namespace {

constexpr double pi = std::numbers::pi;

// x'' + 2 zeta x' + x = cos(omega t): y = (x, v), parameters (frequency, damping).
class ForcedOscillator : public core::HybridOrbitProblem {
 public:
  ForcedOscillator() : HybridOrbitProblem(2, {"frequency", "damping"}) {
    set_parameter("frequency", 1.7);
    set_parameter("damping", 0.1);
    set_free_parameter("damping");
  }
  void field(double t, const double* y, const core::Vector& p, double* dy) const override {
    dy[0] = y[1];
    dy[1] = -y[0] - 2 * p[1] * y[1] + std::cos(p[0] * t);
  }
  bool forced() const override { return true; }
  double forcing_period(const core::Vector& p) const override { return 2 * pi / p[0]; }
  // The exact periodic orbit at t = 0: x = A cos wt + B sin wt.
  core::Vector exact(double omega, double zeta) const {
    const double D = std::pow(1 - omega * omega, 2) + std::pow(2 * zeta * omega, 2);
    core::Vector x(3);
    x << (1 - omega * omega) / D, 2 * zeta * omega / D * omega, zeta;
    return x;
  }
};

// Hopf normal form: a limit cycle of radius sqrt(mu), period 2 pi, multipliers 1 and
// exp(-4 pi mu).
class Hopf : public core::HybridOrbitProblem {
 public:
  Hopf() : HybridOrbitProblem(2, {"mu"}) { set_parameter("mu", 0.25); }
  void field(double, const double* y, const core::Vector& p, double* dy) const override {
    const double r2 = y[0] * y[0] + y[1] * y[1];
    dy[0] = p[0] * y[0] - y[1] - y[0] * r2;
    dy[1] = y[0] + p[0] * y[1] - y[1] * r2;
  }
};

// x'' + x = cos(2.8 t) from its periodic orbit x = c cos(2.8 t), c = 1 / (1 - 2.8^2), with a
// switching surface x = sigma just below the orbit's largest x = |c|: the orbit is beyond it
// for about 2.6e-3 time units per period, far less than a CVODE step at this tolerance.
class Poke : public core::HybridOrbitProblem {
 public:
  explicit Poke(int direction, double below = 1e-6)
      : HybridOrbitProblem(2, {"wall"}), direction_(direction) {
    set_parameter("wall", std::abs(c) - below);
  }
  static constexpr double omega = 2.8;
  static constexpr double c = 1 / (1 - omega * omega);
  void field(double t, const double* y, const core::Vector&, double* dy) const override {
    dy[0] = y[1];
    dy[1] = -y[0] + std::cos(omega * t);
  }
  bool forced() const override { return true; }
  double forcing_period(const core::Vector&) const override { return 2 * pi / omega; }
  int num_events() const override { return 1; }
  double event(int, double, const double* y, const core::Vector& p) const override {
    return y[0] - p[0];
  }
  int event_direction(int) const override { return direction_; }

 private:
  int direction_;
};

// The error of the orbits at rtol 1e-12 over a period is about 1e-11 (measured: 3e-12 on the
// residual); 1e-9 leaves room and still catches any wrong term of the variational equations,
// whose effects are O(1e-2) and more.
constexpr double orbit_tolerance = 1e-9;

void expect_jacobian_matches_differences(const core::Problem& problem, const core::Vector& x) {
  core::Matrix J;
  ASSERT_EQ(problem.jacobian(x, J), core::EvalStatus::ok);
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(x[j]));
    core::Vector plus = x, minus = x, rp, rm;
    plus[j] += h;
    minus[j] -= h;
    ASSERT_EQ(problem.residual(plus, rp), core::EvalStatus::ok);
    ASSERT_EQ(problem.residual(minus, rm), core::EvalStatus::ok);
    // Central differences of step 1e-6 on residuals with 1e-12 noise: errors of about 1e-6
    // (noise / h) plus h^2 times third derivatives of order one.
    EXPECT_LT(((rp - rm) / (2 * h) - J.col(j)).lpNorm<Eigen::Infinity>(), 1e-5) << "column " << j;
  }
}

}  // namespace

TEST(HybridOrbit, ForcedLinearOscillatorHasItsExactOrbitAndMultipliers) {
  ForcedOscillator o;
  const core::Vector x = o.exact(1.7, 0.1);
  core::Vector r;
  ASSERT_EQ(o.residual(x, r), core::EvalStatus::ok);
  EXPECT_LT(r.lpNorm<Eigen::Infinity>(), orbit_tolerance);
  core::Matrix M;
  ASSERT_EQ(o.monodromy(x, M), core::EvalStatus::ok);
  const core::Floquet f = core::analyse_monodromy(M, o.floquet_structure(), {});
  // exp(lambda T), lambda = -zeta +- i sqrt(1 - zeta^2): modulus exp(-zeta T).
  const double T = 2 * pi / 1.7;
  EXPECT_NEAR(f.max_modulus, std::exp(-0.1 * T), orbit_tolerance);
  EXPECT_NEAR(f.determinant, std::exp(-0.2 * T), orbit_tolerance);
  EXPECT_EQ(f.stable, 1);
  EXPECT_EQ(o.floquet_structure().trivial, 0);  // forced: no trivial multiplier
  EXPECT_EQ(o.num_unknowns(), 3);
  EXPECT_EQ(o.num_equations(), 2);
  expect_jacobian_matches_differences(o, x);
  // With the forcing frequency free, the period moves with the parameter (dT / domega).
  ForcedOscillator w;
  w.set_free_parameter("frequency");
  core::Vector xw = o.exact(1.7, 0.1);
  xw[2] = 1.7;
  expect_jacobian_matches_differences(w, xw);
}

TEST(HybridOrbit, AutonomousLimitCycleHasTheTrivialMultiplierAndItsDecay) {
  Hopf h;
  core::Vector x(4);
  x << 0.5, 0.0, 2 * pi, 0.25;  // radius sqrt(0.25), phase: f_0 = 0 at the start
  core::Vector r;
  ASSERT_EQ(h.residual(x, r), core::EvalStatus::ok);
  EXPECT_LT(r.lpNorm<Eigen::Infinity>(), orbit_tolerance);
  core::Matrix M;
  ASSERT_EQ(h.monodromy(x, M), core::EvalStatus::ok);
  const core::Floquet f = core::analyse_monodromy(M, h.floquet_structure(), {});
  EXPECT_EQ(h.floquet_structure().trivial, 1);
  EXPECT_LT(f.trivial_distance, orbit_tolerance);
  EXPECT_NEAR(f.max_modulus, std::exp(-4 * pi * 0.25), orbit_tolerance);
  EXPECT_EQ(f.stable, 1);
  expect_jacobian_matches_differences(h, x);
}

TEST(HybridOrbit, CrossingsWithinOneStepAreNotLost) {
  core::Vector x(3);
  x << Poke::c, 0.0, std::abs(Poke::c) - 1e-6;
  // Both crossings when the event fires either way, the rising one alone otherwise.
  for (const auto& [direction, expected] : {std::pair{0, 2}, std::pair{1, 1}, std::pair{-1, 1}}) {
    Poke poke(direction);
    const core::HybridShot shot = poke.shoot(x);
    ASSERT_TRUE(shot.ok) << shot.message << " failure " << static_cast<int>(shot.failure)
                         << " events " << shot.events.size();
    EXPECT_EQ(static_cast<int>(shot.events.size()), expected) << "direction " << direction;
  }
  // The surface just above the orbit: no event, and the gap is the distance to it.
  Poke above(1, -1e-6);
  x[2] = std::abs(Poke::c) + 1e-6;
  const core::HybridShot shot = above.shoot(x);
  ASSERT_TRUE(shot.ok) << shot.message << " failure " << static_cast<int>(shot.failure)
                       << " events " << shot.events.size();
  EXPECT_TRUE(shot.events.empty());
  EXPECT_NEAR(-shot.extremum[0], 1e-6, 1e-10);
}

TEST(HybridOrbit, GuessesThatCannotStartABranchNameTheirKey) {
  const auto key_of = [](const auto& check) -> std::string {
    try {
      check();
    } catch (const core::InputError& e) {
      return e.key();
    }
    return "none";
  };
  core::Vector x(3);
  x << Poke::c, 0.0, 1.0;  // the surface at x = 1, far above the orbit's |c| = 0.146
  Poke never(1);
  EXPECT_EQ(key_of([&] { never.check_guess(x); }), "event");

  class NanReset : public Poke {
   public:
    NanReset() : Poke(1) {}
    void reset(int, const double*, const core::Vector&, double* y) const override {
      y[0] = y[1] = std::numeric_limits<double>::quiet_NaN();
    }
  } nan_reset;
  x[2] = 0.0;
  EXPECT_EQ(key_of([&] { nan_reset.check_guess(x); }), "reset");

  ForcedOscillator negative;
  negative.set_parameter("frequency", -1.0);
  EXPECT_EQ(key_of([&] { negative.check_guess(negative.exact(1.7, 0.1)); }), "forcing_period");

  Hopf hopf;
  core::Vector y(4);
  y << 0.5, 0.0, -1.0, 0.25;
  EXPECT_EQ(key_of([&] { hopf.check_guess(y); }), "period");
  y[2] = 2 * pi;
  EXPECT_EQ(key_of([&] { hopf.check_guess(y); }), "none");
}
