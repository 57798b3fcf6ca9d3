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
#include "core/io/table.hpp"
#include "core/orbits/periodic_orbit.hpp"

namespace backbone::cli {

namespace {
// A followed family's rank check on its face reads the dimension at a neighbour just inside
// (dimension_flag 3, continuation/README.md 'Following attached branches'); J at the point is
// one side's, so the report above can count less. Says so when branch.csv flags the point.
void print_inside_flag(const std::filesystem::path& branch_csv, int point) {
  if (!std::filesystem::exists(branch_csv)) return;
  const core::Table b = core::Table::read_csv(branch_csv);
  const auto& names = b.columns();
  for (const char* name : {"point", "dimension", "dimension_flag"})
    if (std::find(names.begin(), names.end(), name) == names.end()) return;
  const auto index = b.column("point"), dimension = b.column("dimension"),
             flag = b.column("dimension_flag");
  if (index.empty()) return;
  const double wanted = point < 0 ? index.back() : point;
  for (std::size_t i = 0; i < index.size(); ++i)
    if (index[i] == wanted && flag[i] == 3)
      fmt::print(
          "branch.csv: dimension {} at this point, verified at a neighbour just inside "
          "(dimension_flag 3):\n  the point is on a face of its family, where J is one "
          "side's\n",
          dimension[i]);
}
}  // namespace

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
  // A followed family's folder (DIR/branch_point_K) has its parent's branch.
  const bool followed = dir.filename().string().starts_with("branch_point_") &&
                        std::filesystem::exists(dir.parent_path() / "summary.txt");
  const std::string branch =
      scene.has("branch")
          ? scene.text("branch")
          : core::read_text_value((followed ? dir.parent_path() : dir) / "summary.txt", "branch");
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
  print_inside_flag(dir / "branch.csv", point);
  return e.report.verified_dimension >= 0 ? core::exit_ok : core::exit_numerical_failure;
}

}  // namespace backbone::cli
