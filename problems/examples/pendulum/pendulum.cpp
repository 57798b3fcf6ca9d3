// The conservative pendulum q'' = -sin q, a problem written outside backbone against its
// installed package, with its own CLI (CMakeLists.txt beside this file).
//
// core::OdeOrbitProblem supplies the flow (CVODE), both shooting formulations and the Jacobian;
// the pendulum supplies its acceleration, its stiffness and its energy. Its plugin gives `trace`
// the branch "backbone" (orbits from rest at amplitude A, from the scene's `amplitude`) and one
// benchmark case, `period_error`, that traces A = 0.1 .. 3 and checks every period against the
// exact one,
//     T(A) = 4 K(m),  m = sin^2(A/2),  K(m) = pi / (2 AGM(1, cos(A/2))),
// the complete elliptic integral of the first kind by the arithmetic-geometric mean.
//
//   pendulum_backbone trace scenes/pendulum.ini --out out/pendulum
//   pendulum_backbone bench --case period_error --out out/bench    # exit 1 if an error > 1e-9,
//                                                                   # out/bench/period_error.csv
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>

#include "continuation/cli/plugin.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "core/io/table.hpp"
#include "core/orbits/ode_orbit.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::pendulum {

namespace {

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

// Exact period at amplitude 0 < A < pi. cos(A/2) = sqrt(1 - m) is taken directly, which avoids
// the cancellation in 1 - m near A = pi; the AGM converges quadratically to rounding.
double exact_period(double amplitude) {
  double a = 1.0, b = std::cos(amplitude / 2);
  for (int i = 0; i < 64 && std::abs(a - b) > 1e-15 * a; ++i) {
    const double mean = (a + b) / 2;
    b = std::sqrt(a * b);
    a = mean;
  }
  return 4.0 * std::numbers::pi / (2.0 * a);
}

double relative_period_error(const core::Vector& x) {
  const double exact = exact_period(x[0]);
  return std::abs(x[1] - exact) / exact;
}

boost::program_options::options_description scene_keys() {
  namespace po = boost::program_options;
  po::options_description keys("pendulum (q'' = -sin q)");
  keys.add_options()("amplitude", po::value<double>()->default_value(0.1),
                     "starting amplitude A of the backbone, 0 < A < pi [rad]");
  return keys;
}

cli::TraceSetup setup_trace(const core::Scene& scene, const std::string&) {
  cli::TraceSetup s;
  s.problem = std::make_unique<Pendulum>();
  s.guess.resize(2);
  s.guess << scene.positive("amplitude"), 2.0 * std::numbers::pi;  // the linear period
  s.direction = core::Vector::Unit(2, 0);                          // amplitude grows
  s.describe_point = [](const continuation::BranchPoint& p) {
    return fmt::format("exact period rel err {:.2e}", relative_period_error(p.x));
  };
  return s;
}

// `bench --case period_error`: A = 0.1 .. 3 with a tight corrector; exit 1 unless every
// period is within 1e-9 of the exact one and the branch reaches A = 3.
int period_error(const std::filesystem::path& out) {
  Pendulum pendulum;
  core::NewtonOptions newton_options;
  // ||F|| <= 1e-12 on the dimensionless residual: a simple root with dF/dT of order 1, so the
  // period is pinned to ~1e-12 relative, well inside the 1e-9 requirement.
  newton_options.residual_tolerance = 1e-12;
  auto newton = core::make_corrector("kinsol", newton_options);
  continuation::ContinuationOptions options;
  options.ds = 0.05;
  options.ds_max = 0.5;
  options.bounds.push_back({"amplitude", 0.0, 3.0});
  core::Vector guess(2), direction(2);
  guess << 0.1, 2.0 * std::numbers::pi;
  direction << 1.0, 0.0;
  const continuation::Branch branch =
      continuation::pseudo_arclength(pendulum, guess, direction, *newton, options, {});
  double worst = 0;
  core::Table table({"amplitude", "period", "exact_period", "relative_error"});
  for (const continuation::BranchPoint& p : branch.points) {
    worst = std::max(worst, relative_period_error(p.x));
    table.add_row({p.x[0], p.x[1], exact_period(p.x[0]), relative_period_error(p.x)});
  }
  std::filesystem::create_directories(out);
  table.write_csv(out / "period_error.csv");
  const bool reached = branch.reason == continuation::StopReason::bound_reached &&
                       std::abs(branch.points.back().x[0] - 3.0) < 1e-9;
  fmt::print(
      "period_error: {} points to A = {:.6f}, worst relative period error {:.3e} "
      "(limit 1e-9) -> {}\n",
      branch.points.size(), branch.points.empty() ? 0.0 : branch.points.back().x[0], worst,
      reached && worst <= 1e-9 ? "ok" : "FAIL");
  return reached && worst <= 1e-9 ? 0 : 1;
}

}  // namespace

void register_plugin(cli::PluginRegistry& registry) {
  cli::ProblemPlugin p;
  p.name = "pendulum";
  p.summary = "conservative pendulum q'' = -sin q";
  p.scene_keys = &scene_keys;
  p.branches = {"backbone"};
  p.setup = &setup_trace;
  p.units = {{"period", "s"}, {"frequency", "rad/s"}, {"energy", "J/kg"}, {"amplitude", "rad"}};
  p.bench_cases = {
      {"period_error", "periods of A = 0.1 .. 3 against the exact period", period_error}};
  registry.add(std::move(p));
}

}  // namespace backbone::pendulum
