// Registers the Duffing oscillator with `backbone trace` (branch "backbone": the family of
// periodic orbits starting at rest at amplitude x0, followed from the scene's amplitude).
#include <numbers>

#include "drivers/trace_registry.hpp"
#include "problems/duffing/duffing.hpp"

namespace {

using namespace backbone;

drivers::TraceSetup setup_duffing(const core::Scene& scene, const std::string&) {
  duffing::DuffingOptions options;
  options.relative_tolerance = scene.positive("rtol");
  drivers::TraceSetup s;
  s.problem = std::make_unique<duffing::Duffing>(options);
  const double amplitude = scene.positive("amplitude");
  const double period =
      scene.has("period_guess") ? scene.positive("period_guess") : 2.0 * std::numbers::pi;
  s.guess.resize(2);
  s.guess << amplitude, period;
  s.direction = core::Vector::Unit(2, 0);  // amplitude grows; the first point keeps x0 fixed
  return s;
}

}  // namespace

static const bool registered =
    drivers::register_trace_problem({"duffing",
                                     "conservative Duffing oscillator x'' + x + x^3 = 0",
                                     &duffing::scene_keys,
                                     {"backbone"},
                                     setup_duffing});
