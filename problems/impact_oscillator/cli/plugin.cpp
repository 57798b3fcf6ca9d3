// The impact oscillator as a CLI plugin (continuation/cli/plugin.hpp): `trace` branch "period1",
// the orbit with one impact per forcing period, started on its closed form at the scene's
// parameters and continued in one of them (continuation_parameter, the wall by default) within
// [wall_min, wall_max]; and its steps of the main job.
//
//   backbone trace problems/impact_oscillator/scenes/impact.ini --out out/impact
#include "continuation/cli/plugin.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "core/errors.hpp"
#include "problems/impact_oscillator/figures.hpp"
#include "problems/impact_oscillator/impact_oscillator.hpp"

namespace backbone::impact_oscillator {

namespace {

cli::TraceSetup setup_trace(const core::Scene& scene, const std::string&) {
  core::HybridOrbitOptions options;
  options.relative_tolerance = scene.positive("rtol");
  const double omega = scene.positive("frequency");
  if (std::abs(std::remainder(omega, 1.0)) < 1e-9)
    throw core::InputError("frequency",
                           fmt::format("must not be a whole number (got {}: the forcing resonates "
                                       "with the free oscillation and no period-1 orbit exists)",
                                       omega));
  const double r = scene.positive("restitution");
  if (!(r <= 1))
    throw core::InputError("restitution", fmt::format("must be in (0, 1] (got {})", r));
  const double sigma = scene.number("wall");
  const double wall_min = scene.number("wall_min"), wall_max = scene.number("wall_max");
  if (!(wall_min < sigma))
    throw core::InputError("wall_min",
                           fmt::format("must be below wall = {} (got {})", sigma, wall_min));
  if (!(wall_max > sigma))
    throw core::InputError("wall_max",
                           fmt::format("must be above wall = {} (got {})", sigma, wall_max));
  const double grazing_velocity = scene.positive("grazing_velocity");
  const double grazing_gap = scene.positive("grazing_gap");
  const std::string free =
      scene.choice("continuation_parameter", {"wall", "restitution", "frequency"});

  auto problem = std::make_unique<ImpactOscillator>(options);
  problem->set_parameter("frequency", omega);
  problem->set_parameter("restitution", r);
  problem->set_parameter("wall", sigma);
  problem->set_free_parameter(free);
  const auto orbit = period_one_orbit(omega, r, sigma);
  if (!orbit)
    throw core::InputError("wall", fmt::format("no period-1 orbit with one impact exists at "
                                               "wall = {} (it lies beyond the grazing wall {})",
                                               sigma, std::abs(1 / (1 - omega * omega))));
  cli::TraceSetup s;
  s.guess.resize(3);
  s.guess << orbit->start, problem->parameters()[problem->free_parameter()];
  problem->check_guess(s.guess);
  s.direction = core::Vector::Unit(3, 2);  // the free parameter grows
  s.branch_options = [wall_min, wall_max, free, grazing_velocity, grazing_gap](
                         cli::ContinuationOptions& continuation, core::NewtonOptions&) {
    if (free == "wall")
      continuation.bounds.push_back({"wall", wall_min, wall_max, "wall_min", "wall_max"});
    const double inf = std::numeric_limits<double>::infinity();
    continuation.bounds.push_back(
        {"impact_velocity", grazing_velocity, inf, "grazing_velocity", "impact_velocity"});
    continuation.bounds.push_back({"wall_gap", grazing_gap, inf, "grazing_gap", "wall_gap"});
  };
  s.describe_point = [](const cli::BranchPoint& point) {
    const auto oracle = period_one_orbit(point.observable("frequency"),
                                         point.observable("restitution"), point.observable("wall"));
    if (!oracle || point.observable("impacts_per_period") != 1) return std::string();
    return fmt::format("closed-form impact velocity rel err {:.1e}",
                       std::abs(point.observable("impact_velocity") / oracle->impact_velocity - 1));
  };
  s.problem = std::move(problem);
  return s;
}

}  // namespace

void register_plugin(cli::PluginRegistry& registry) {
  cli::ProblemPlugin p;
  p.name = "impact_oscillator";
  p.summary =
      "harmonically forced impact oscillator x'' + x = cos(omega t), v -> -r v at x = sigma";
  p.scene_keys = &scene_keys;
  p.branches = {"period1"};
  p.setup = &setup_trace;
  p.branch_axes = {"wall", "impact_velocity"};
  p.figures = figure_jobs();
  const std::string scene = "problems/impact_oscillator/scenes/impact.ini";
  const std::string folder = "{out}/impact_oscillator/";
  // Per restitution: up from sigma = 0 to the grazing, then down to -0.2 from the same first
  // point, switching onto the period-2 branch at the period doubling.
  for (const auto& [name, r] : {std::pair{"dissipative", "0.8"}, std::pair{"elastic", "1"}}) {
    p.reproduce.push_back({fmt::format("impact_{}_up", name),
                           "trace",
                           {scene, "--restitution", r, "--out", folder + name + "_up"}});
    p.reproduce.push_back(
        {fmt::format("impact_{}_down", name),
         "trace",
         {scene, "--restitution", r, "--start", folder + name + "_up:0", "--direction", "-1",
          "--follow", "doubling", "--out", folder + name + "_down"}});
  }
  registry.add(std::move(p));
}

}  // namespace backbone::impact_oscillator
