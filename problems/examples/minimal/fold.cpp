// The smallest problem of a backbone CLI: the parabola x^2 + lambda - 1 = 0 in the unknowns
// (x, lambda), a curve with a fold in lambda at (0, 1). A core::Problem gives its sizes and its
// residual (the Jacobian defaults to finite differences); the plugin gives `trace` one branch
// and its start. Every point is checked against the curve itself: describe_point prints the
// distance |lambda - (1 - x^2)| on each progress line.
//
//   minimal_backbone trace scenes/fold.ini --out out/fold      # x from -1.5 to 1.5
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "continuation/cli/plugin.hpp"
#include "core/problem.hpp"

namespace backbone::fold {

namespace {

class Parabola : public core::Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  std::string name() const override { return "fold"; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"x", x[0]}, {"lambda", x[1]}};
  }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(1);
    r[0] = x[0] * x[0] + x[1] - 1.0;
    return core::EvalStatus::ok;
  }
};

boost::program_options::options_description scene_keys() {
  namespace po = boost::program_options;
  po::options_description keys("fold (x^2 + lambda - 1 = 0)");
  keys.add_options()("x_start", po::value<double>()->default_value(-1.5), "starting x [-]");
  return keys;
}

cli::TraceSetup setup_trace(const core::Scene& scene, const std::string&) {
  cli::TraceSetup s;
  s.problem = std::make_unique<Parabola>();
  const double x = scene.number("x_start");
  s.guess.resize(2);
  s.guess << x, 1.0 - x * x;
  s.direction = core::Vector::Unit(2, 0);  // x increases: lambda rises to 1, then falls
  s.describe_point = [](const continuation::BranchPoint& p) {
    return fmt::format("off the curve {:.1e}", std::abs(p.x[1] - (1.0 - p.x[0] * p.x[0])));
  };
  return s;
}

}  // namespace

void register_plugin(cli::PluginRegistry& registry) {
  cli::ProblemPlugin p;
  p.name = "fold";
  p.summary = "the parabola x^2 + lambda - 1 = 0, a fold in lambda";
  p.scene_keys = &scene_keys;
  p.branches = {"parabola"};
  p.setup = &setup_trace;
  registry.add(std::move(p));
}

}  // namespace backbone::fold
