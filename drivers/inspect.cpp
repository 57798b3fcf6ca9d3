// `backbone inspect SCENE --orbit DIR/orbits.csv:K [--branch NAME] [--key value ...]`: the
// dimension of the solution set at point K of a traced branch, with its evidence (singular
// values, threshold, gap, each probe and its distance; problems/contact_bar/inspect.hpp). The
// plugin's setup builds the problem from the scene (the branch of DIR/summary.txt unless
// --branch); the point is DIR/unknowns.csv's. Pass the trace's grid keys (or DIR/scene.ini).
#include "problems/contact_bar/inspect.hpp"

#include <fmt/format.h>

#include "continuation/outputs.hpp"
#include "continuation/scene_options.hpp"
#include "core/errors.hpp"
#include "core/periodic_orbit.hpp"
#include "core/scene_ini.hpp"
#include "drivers/commands.hpp"
#include "drivers/plugins.hpp"

namespace backbone::drivers {
namespace {
namespace po = boost::program_options;

int run_inspect(const std::vector<std::string>& args) {
  if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
  const continuation::ProblemPlugin& entry = plugin_for_scene(args[0], "trace");
  po::options_description keys = entry.scene_keys(), own("inspect");
  own.add_options()("orbit", po::value<std::string>()->required(), "DIR/orbits.csv:K")  //
      ("branch", po::value<std::string>(), "branch of the problem (default: DIR's)");
  keys.add(continuation::continuation_keys(keys));
  const core::Scene scene = core::read_scene(keys, args[0], {args.begin() + 1, args.end()}, own);
  if (!scene.has("orbit")) throw core::InputError("orbit", "needs DIR/orbits.csv:K");
  const auto [dir, point] = continuation::parse_saved_point(scene.text("orbit"), "orbit");
  const std::string branch = scene.has("branch")
                                 ? scene.text("branch")
                                 : core::read_text_value(dir / "summary.txt", "branch");
  const continuation::RunSettings run = continuation::read_run_settings(scene);
  continuation::TraceSetup setup = entry.setup(scene, branch);
  if (auto* periodic = dynamic_cast<core::PeriodicOrbitProblem*>(setup.problem.get()))
    periodic->set_formulation(run.formulation);
  const core::Vector x = continuation::read_unknowns(dir / "unknowns.csv", point, "orbit");
  if (x.size() != setup.problem->num_unknowns())
    throw core::InputError("orbit", fmt::format("the point has {} unknowns, the problem {} (same "
                                                "grid keys as the trace?)",
                                                x.size(), setup.problem->num_unknowns()));
  const auto e = contact_bar::dimension_evidence(*setup.problem, x, run.options.rank,
                                                 run.options.verification);
  fmt::print("{} / {} point {}: {} equations, {} unknowns\n{}", entry.name, branch, point,
             setup.problem->num_equations(), x.size(), e.text());
  return e.report.verified_dimension >= 0 ? core::exit_ok : core::exit_numerical_failure;
}

const bool registered =
    register_command({"inspect", "SCENE --orbit DIR/orbits.csv:K",
                      "dimension of a traced point, with evidence", run_inspect});
}  // namespace
}  // namespace backbone::drivers
