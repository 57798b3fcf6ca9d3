// A forced oscillator with a one-sided spring beyond a gap, as a hybrid problem outside the tree:
//
//     x'' + 2 zeta x' + x + k max(x - gap, 0) = cos(omega t),
//
// a core::HybridOrbitProblem (core/orbits/hybrid_orbit.hpp) with one event, the contact x = gap
// in either direction, and no jump (the default reset): the event stops the integration at the
// spring's kink so that each segment is smooth. The orbit's period is the forcing's, 2 pi /
// omega, and the branch runs in omega (the problem's free parameter). The contact need not
// happen (event_required: false): far from resonance the orbit stays below the gap.
//
// A check of every point: the field's divergence is -2 zeta on both sides and the reset is the
// identity, so det M = exp(-2 zeta T) exactly (Liouville); describe_point prints its error.
//
//   bilinear_backbone trace scenes/bilinear.ini --out out/bilinear
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "continuation/cli/plugin.hpp"
#include "core/errors.hpp"
#include "core/orbits/hybrid_orbit.hpp"

namespace backbone::bilinear {

namespace {

constexpr int frequency = 0, damping = 1, gap = 2, stiffness = 3;

class Bilinear : public core::HybridOrbitProblem {
 public:
  Bilinear() : HybridOrbitProblem(2, {"frequency", "damping", "gap", "stiffness"}) {}
  std::string name() const override { return "bilinear"; }
  std::unique_ptr<core::Problem> clone() const override {
    return std::make_unique<Bilinear>(*this);
  }
  void field(double t, const double* y, const core::Vector& p, double* dy) const override {
    dy[0] = y[1];
    dy[1] = -y[0] - 2 * p[damping] * y[1] - p[stiffness] * std::max(y[0] - p[gap], 0.0) +
            std::cos(p[frequency] * t);
  }
  bool forced() const override { return true; }
  double forcing_period(const core::Vector& p) const override {
    return 2 * std::numbers::pi / p[frequency];
  }
  int num_events() const override { return 1; }
  double event(int, double, const double* y, const core::Vector& p) const override {
    return y[0] - p[gap];
  }
  int event_direction(int) const override { return 0; }
  bool event_required(int) const override { return false; }
  std::string event_count_name() const override { return "contacts_per_period"; }
  std::string event_speed_name() const override { return "contact_velocity"; }
  std::string event_gap_name() const override { return "gap_left"; }
};

boost::program_options::options_description scene_keys() {
  namespace po = boost::program_options;
  po::options_description keys("bilinear (x'' + 2 zeta x' + x + k max(x - gap, 0) = cos(omega t))");
  keys.add_options()                                                                              //
      ("frequency", po::value<double>()->default_value(0.5), "starting forcing frequency (> 0)")  //
      ("damping", po::value<double>()->default_value(0.05), "damping ratio zeta (> 0)")           //
      ("gap", po::value<double>()->default_value(1.0), "gap before the spring (> 0)")             //
      ("stiffness", po::value<double>()->default_value(4.0), "spring stiffness k (>= 0)");
  return keys;
}

cli::TraceSetup setup_trace(const core::Scene& scene, const std::string&) {
  auto problem = std::make_unique<Bilinear>();
  const double omega = scene.positive("frequency"), zeta = scene.positive("damping");
  problem->set_parameter("frequency", omega);
  problem->set_parameter("damping", zeta);
  problem->set_parameter("gap", scene.positive("gap"));
  problem->set_parameter("stiffness", scene.non_negative("stiffness"));
  problem->set_free_parameter("frequency");
  // The linear oscillator's orbit as the guess: A cos wt + B sin wt.
  const double D = std::pow(1 - omega * omega, 2) + std::pow(2 * zeta * omega, 2);
  cli::TraceSetup s;
  s.guess.resize(3);
  s.guess << (1 - omega * omega) / D, 2 * zeta * omega * omega / D, omega;
  problem->check_guess(s.guess);  // InputError before any work (a period <= 0, a NaN reset)
  s.direction = core::Vector::Unit(3, 2);
  s.describe_point = [zeta](const continuation::BranchPoint& p) {
    if (!p.floquet) return std::string();
    const double T = p.observable("period");
    return fmt::format("det M - exp(-2 zeta T) {:.1e}",
                       p.floquet->determinant - std::exp(-2 * zeta * T));
  };
  s.problem = std::move(problem);
  return s;
}

}  // namespace

void register_plugin(cli::PluginRegistry& registry) {
  cli::ProblemPlugin p;
  p.name = "bilinear";
  p.summary = "forced oscillator with a one-sided spring beyond a gap (a hybrid problem)";
  p.scene_keys = &scene_keys;
  p.branches = {"response"};
  p.setup = &setup_trace;
  registry.add(std::move(p));
}

}  // namespace backbone::bilinear
