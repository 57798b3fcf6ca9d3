// The Duffing oscillator as a CLI plugin (continuation/cli/plugin.hpp): `trace` branch "backbone",
// the family of periodic orbits starting at rest at amplitude x0, followed from the scene's
// amplitude, and its step of the main job.
//
//   backbone trace problems/duffing/scenes/duffing.ini --branch backbone --out out/duffing
#include "continuation/cli/plugin.hpp"

#include <fmt/format.h>

#include <memory>
#include <numbers>

#include "core/errors.hpp"
#include "problems/duffing/bench/bench.hpp"
#include "problems/duffing/duffing.hpp"

namespace backbone::duffing {

namespace {

cli::TraceSetup setup_trace(const core::Scene& scene, const std::string&) {
  DuffingOptions options;
  options.relative_tolerance = scene.positive("rtol");
  cli::TraceSetup s;
  s.problem = std::make_unique<Duffing>(options);
  const double amplitude = scene.positive("amplitude");
  const double period =
      scene.has("period_guess") ? scene.positive("period_guess") : 2.0 * std::numbers::pi;
  // The hardening backbone's periods lie below the linear 2 pi; a guess far above it would have
  // CVODE integrate for thousands of periods before Newton could refuse it.
  if (period > 20 * std::numbers::pi)
    throw core::InputError(
        "period_guess",
        fmt::format("must be in (0, 20 pi] (the linear period is 2 pi; got {})", period));
  s.guess.resize(2);
  s.guess << amplitude, period;
  s.direction = core::Vector::Unit(2, 0);  // amplitude grows; the first point keeps x0 fixed
  return s;
}

}  // namespace

void register_plugin(cli::PluginRegistry& registry) {
  cli::ProblemPlugin p;
  p.name = "duffing";
  p.summary = "conservative Duffing oscillator x'' + x + x^3 = 0";
  p.scene_keys = &scene_keys;
  p.branches = {"backbone"};
  p.setup = &setup_trace;
  p.bench_cases = bench_cases();
  p.reproduce = {
      {"duffing",
       "trace",
       {"problems/duffing/scenes/duffing.ini", "--branch", "backbone", "--out", "{out}/duffing"}},
      // Into the contact bar's bench folder: BENCHMARKS.md there gathers every case's section.
      {"bench_duffing", "bench", {"--problem", "duffing", "--out", "{out}/bench"}}};
  registry.add(std::move(p));
}

}  // namespace backbone::duffing
