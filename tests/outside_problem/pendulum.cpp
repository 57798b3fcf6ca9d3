// A problem written outside backbone, against its installed package: the conservative pendulum
// q'' = -sin q as a periodic-orbit problem (core::OdeOrbitProblem supplies the flow, both
// shooting formulations and the analytic Jacobian; the pendulum supplies its acceleration, its
// stiffness and its energy). The program traces the backbone from amplitude 0.1 to 3.0 with
// pseudo-arclength continuation and checks every point against the exact period
//     T(A) = 4 K(m),  m = sin^2(A/2),  K(m) = pi / (2 AGM(1, sqrt(1 - m))),
// the complete elliptic integral of the first kind by the arithmetic-geometric mean. It prints
// one line per point and the worst relative period error, and exits 1 if that exceeds 1e-9 (or
// the branch did not reach A = 3), 0 otherwise. Build it with CMAKE_PREFIX_PATH set to the
// install prefix of backbone (see README.md next to this file).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "continuation/pseudo_arclength.hpp"
#include "core/newton.hpp"
#include "core/ode_orbit.hpp"

using namespace backbone;

class Pendulum : public core::OdeOrbitProblem {
 public:
  Pendulum() : OdeOrbitProblem(1) {}
  std::string name() const override { return "pendulum"; }
  void acceleration(const double* q, double* a) const override { a[0] = -std::sin(q[0]); }
  void acceleration_jacobian(const double* q, core::Matrix& J) const override {
    J.resize(1, 1);
    J(0, 0) = -std::cos(q[0]);
  }
  // Potential energy at the turning point q0 (the orbit starts at rest).
  double energy(const core::Vector& x) const override { return 1.0 - std::cos(x[0]); }
  core::Observables observables(const core::Vector& x) const override {
    core::Observables o = OdeOrbitProblem::observables(x);  // period, frequency, energy
    o.emplace_back("amplitude", x[0]);
    return o;
  }
  // Amplitudes of order 1, periods of order 2 pi: the continuation steps in these units.
  core::Vector typical_scale() const override {
    core::Vector s(2);
    s << 1.0, 2.0 * std::numbers::pi;
    return s;
  }
};

// Exact period of the pendulum of amplitude 0 < A < pi. sqrt(1 - m) = cos(A/2) is taken
// directly, which avoids the cancellation in 1 - m near A = pi; the AGM converges
// quadratically, so a handful of iterations reach rounding (it agrees with
// std::comp_ellint_1 to 1e-15).
double exact_period(double amplitude) {
  double a = 1.0, b = std::cos(amplitude / 2);
  for (int i = 0; i < 64 && std::abs(a - b) > 1e-15 * a; ++i) {
    const double mean = (a + b) / 2;
    b = std::sqrt(a * b);
    a = mean;
  }
  return 4.0 * std::numbers::pi / (2.0 * a);
}

int main() {
  Pendulum pendulum;
  // ||F|| <= 1e-12 on the dimensionless residual v(T/2) / v_max: a simple root with dF/dT of
  // order 1, so the period is pinned to ~1e-12 relative, well inside the 1e-9 requirement.
  core::NewtonOptions newton_options;
  newton_options.residual_tolerance = 1e-12;
  auto newton = core::make_corrector("kinsol", newton_options);

  continuation::ContinuationOptions options;
  options.ds = 0.05;
  options.ds_max = 0.5;
  options.rank_check_every = 10;  // the rank report confirms a curve (dimension 1)
  options.bounds.push_back({"amplitude", 0.0, 3.0});

  double worst = 0;
  continuation::ContinuationHooks hooks;
  hooks.on_point = [&](const continuation::BranchPoint& p) {
    const double amplitude = p.x[0], period = p.x[pendulum.period_index()];
    const double exact = exact_period(amplitude);
    const double error = std::abs(period - exact) / exact;
    worst = std::max(worst, error);
    std::printf("%3d  A = %.6f  T = %.15f  exact %.15f  rel. error %.2e  dim %d\n", p.index,
                amplitude, period, exact, error, p.dimension);
  };
  core::Vector guess(2), direction(2);
  guess << 0.1, 2.0 * std::numbers::pi;  // the small-amplitude period; the corrector fixes it
  direction << 1.0, 0.0;                 // amplitude grows
  const continuation::Branch branch =
      continuation::pseudo_arclength(pendulum, guess, direction, *newton, options, hooks);

  const bool reached_end = branch.reason == continuation::StopReason::bound_reached &&
                           std::abs(branch.points.back().x[0] - 3.0) < 1e-9;
  std::printf("%zu points, %s; worst relative period error %.3e (limit 1e-9)\n",
              branch.points.size(), branch.message.c_str(), worst);
  if (!reached_end) std::printf("FAIL: the branch did not reach amplitude 3.0\n");
  if (worst > 1e-9) std::printf("FAIL: period error above 1e-9\n");
  return reached_end && worst <= 1e-9 ? 0 : 1;
}
