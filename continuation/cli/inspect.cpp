#include "continuation/cli/inspect.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>

#include "continuation/cli/scene_options.hpp"
#include "continuation/dimension_evidence.hpp"
#include "continuation/outputs.hpp"
#include "core/errors.hpp"
#include "core/io/scene_ini.hpp"
#include "core/orbits/periodic_orbit.hpp"

namespace backbone::cli {

int inspect_command(const ProblemPlugin& plugin, const std::vector<std::string>& args) {
  namespace po = boost::program_options;
  if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
  po::options_description keys = plugin.scene_keys(), own("inspect");
  own.add_options()("orbit", po::value<std::string>(), "DIR/orbits.csv:K")  //
      ("branch", po::value<std::string>(), "branch of the problem (default: DIR's)");
  keys.add(continuation_keys(keys));
  const core::Scene scene = core::read_scene(keys, args[0], {args.begin() + 1, args.end()}, own);
  if (!scene.has("orbit")) throw core::InputError("orbit", "needs DIR/orbits.csv:K");
  const auto [dir, point] = continuation::parse_saved_point(scene.text("orbit"), "orbit");
  if (!std::filesystem::exists(dir / "unknowns.csv"))
    throw core::InputError(
        "orbit", fmt::format("'{}' holds no traced branch (no unknowns.csv)", dir.string()));
  const std::string branch = scene.has("branch")
                                 ? scene.text("branch")
                                 : core::read_text_value(dir / "summary.txt", "branch");
  if (!plugin.has_branch(branch))
    throw core::InputError(scene.has("branch") ? "branch" : "orbit",
                           fmt::format("'{}' is not a branch of {} (known: {})", branch,
                                       plugin.name, plugin.branch_list()));
  const RunSettings run = read_run_settings(scene);
  TraceSetup setup = plugin.setup(scene, branch);
  if (auto* periodic = dynamic_cast<core::PeriodicOrbitProblem*>(setup.problem.get()))
    periodic->set_formulation(run.formulation);
  const core::Vector x = continuation::read_unknowns(dir / "unknowns.csv", point, "orbit");
  if (x.size() != setup.problem->num_unknowns())
    throw core::InputError("orbit", fmt::format("the point has {} unknowns, the problem {} (same "
                                                "grid keys as the trace?)",
                                                x.size(), setup.problem->num_unknowns()));
  // The next point of the branch (else the previous one) as the neighbour, when there is one.
  core::Vector neighbour;
  for (const int other : {point + 1, point - 1}) {
    if (point < 0 || other < 0 || neighbour.size() > 0) continue;  // point -1: the last
    try {
      neighbour = continuation::read_unknowns(dir / "unknowns.csv", other, "orbit");
    } catch (const core::InputError&) {
    }
  }
  const continuation::DimensionEvidence e = continuation::dimension_evidence(
      *setup.problem, x, run.options.rank, run.options.verification, neighbour);
  fmt::print("{} / {} point {}: {} equations, {} unknowns\n{}", plugin.name, branch, point,
             setup.problem->num_equations(), x.size(), e.text());
  return e.report.verified_dimension >= 0 ? core::exit_ok : core::exit_numerical_failure;
}

}  // namespace backbone::cli
