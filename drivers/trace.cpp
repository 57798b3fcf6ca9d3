// `backbone trace SCENE --branch NAME [--out DIR] [--key value ...]`: follows a family of
// solutions (a nonlinear mode) by continuation and writes DIR/branch.csv, DIR/orbits.csv,
// DIR/branch.png and DIR/summary.txt.
//
// The scene's `problem` key picks a plugin (continuation/plugin.hpp); its setup builds the
// problem and the guess. Continuation settings are scene keys too (continuation/
// scene_options.hpp; defaults < scene file < command line). Bad input throws core::InputError
// before anything is written (exit 2). A branch that ends early keeps and writes its points
// (exit 0, reason printed and in summary.txt); exit 1 only when no point converged.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "continuation/outputs.hpp"
#include "continuation/scene_options.hpp"
#include "core/errors.hpp"
#include "core/output_folder.hpp"
#include "core/periodic_orbit.hpp"
#include "core/plot.hpp"
#include "core/scene.hpp"
#include "core/table.hpp"
#include "drivers/commands.hpp"
#include "drivers/plugins.hpp"

namespace backbone::drivers {
namespace {

namespace po = boost::program_options;
namespace cont = backbone::continuation;

po::options_description driver_keys() {
  po::options_description keys("trace");
  keys.add_options()                                                                             //
      ("branch", po::value<std::string>(), "branch to follow (the problem lists its branches)")  //
      ("out", po::value<std::string>(), "output directory (default out/PROBLEM_BRANCH)")         //
      ("help", "describe the command, the problem's keys and the continuation keys");
  return keys;
}

std::string joined(const std::vector<std::string>& words) {
  std::string list;
  for (const auto& w : words) list += (list.empty() ? "" : ", ") + w;
  return list;
}

void print_help(const cont::ProblemPlugin* problem) {
  fmt::print("usage: backbone trace SCENE [--branch NAME] [--out DIR] [--key value ...]\n\n");
  fmt::print("problems (scene key `problem`):\n");
  for (const auto& p : plugins().all())
    if (p.can_trace())
      fmt::print("  {:<14} {} (branches: {})\n", p.name, p.summary, joined(p.branches));
  std::ostringstream text;
  text << "\n" << driver_keys() << "\n";
  if (problem) {
    const po::options_description keys = problem->scene_keys();
    text << keys << "\n" << cont::continuation_keys(keys);
  } else {
    text << cont::continuation_keys(po::options_description())
         << "\n(defaults of a problem's own keys: backbone trace SCENE --help)\n";
  }
  fmt::print("{}\n", text.str());
}

// The figure: frequency against energy (log axis) when the problem reports them, else the
// first two observables.
void write_figure(const std::filesystem::path& out, const core::Table& table,
                  const std::string& title) {
  const auto& columns = table.columns();
  const auto column_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i) + 1;
    return 0;
  };
  int x = column_of("energy"), y = column_of("frequency");
  bool log_x = x > 0 && y > 0;
  if (!log_x) {
    x = 2;
    y = 3;
  }
  if (static_cast<int>(columns.size()) < std::max(x, y)) return;
  const std::string script = fmt::format(
      "set datafile separator ','\nset key top left\nset grid\n{}"
      "set xlabel '{}'\nset ylabel '{}'\nset title '{}' noenhanced\n"
      "plot {} using {}:{} skip 1 with linespoints pt 7 ps 0.6 title 'branch'\n",
      log_x ? "set logscale x\nset format x '10^{%L}'\n" : "", columns[x - 1],
      columns[y - 1] + (columns[y - 1] == "frequency" ? " [rad/time]" : ""), title,
      core::gnuplot_quote(out / "branch.csv"), x, y);
  core::PlotResult r = core::render_png(out / "branch.png", script);
  if (!r.ok) fmt::print(stderr, "figure skipped: {}\n", r.message);
}

int run_trace(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    print_help(nullptr);
    if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
    return core::exit_ok;
  }
  const std::string scene_path = args[0];
  const cont::ProblemPlugin& entry = plugin_for_scene(scene_path, "trace");
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (std::find_if(rest.begin(), rest.end(),
                   [](const std::string& a) { return a == "--help" || a == "-h"; }) != rest.end()) {
    print_help(&entry);
    return core::exit_ok;
  }

  po::options_description keys = entry.scene_keys();
  keys.add(cont::continuation_keys(keys));
  const core::Scene scene = core::read_scene(keys, scene_path, rest, driver_keys());
  const std::string branch_name = scene.has("branch") ? scene.text("branch") : entry.branches.at(0);
  if (std::find(entry.branches.begin(), entry.branches.end(), branch_name) == entry.branches.end())
    throw core::InputError("branch", fmt::format("'{}' is not a branch of {} (known: {})",
                                                 branch_name, entry.name, joined(entry.branches)));
  const std::filesystem::path out =
      scene.has("out") ? scene.text("out") : fmt::format("out/{}_{}", entry.name, branch_name);
  core::check_output_folder("out", out);
  const cont::RunSettings run = cont::read_run_settings(scene);
  const cont::ContinuationOptions& options = run.options;
  auto corrector = core::make_corrector(run.newton, run.newton_options);

  cont::TraceSetup setup = entry.setup(scene, branch_name);
  if (!setup.problem) throw core::InputError("problem", "setup returned no problem");
  const core::Problem& problem = *setup.problem;
  auto* periodic = dynamic_cast<core::PeriodicOrbitProblem*>(setup.problem.get());
  if (periodic) periodic->set_formulation(run.formulation);
  core::Vector direction = setup.direction;
  if (direction.size() == 0)
    direction = core::Vector::Unit(
        problem.num_unknowns(), periodic ? periodic->period_index() : problem.num_unknowns() - 1);

  const int n = problem.num_unknowns(), m = problem.num_equations();
  if (m != n - 1 && corrector->name() == "kinsol")
    throw core::InputError("newton", fmt::format("kinsol solves square systems only; this {} "
                                                 "residual has {} equations for {} unknowns "
                                                 "(use newton = eigen, least squares)",
                                                 entry.name, m, n));
  // A consistent overdetermined system (m > n - 1) still has curves of solutions.
  const int expected_dimension = n - std::min(m, n - 1);
  fmt::print("{} / {}: {} equations in {} unknowns, expected manifold dimension {}\n", entry.name,
             branch_name, m, n, expected_dimension);
  fmt::print("  {} continuation, {} predictor, newton {}, {}{}\n", cont::to_string(options.method),
             cont::to_string(options.predictor), corrector->name(),
             periodic ? fmt::format("formulation {}, ", core::to_string(run.formulation)) : "",
             fmt::format("ds {:g} in [{:g}, {:g}], at most {} points", options.ds, options.ds_min,
                         options.ds_max, options.max_points));

  cont::ContinuationHooks hooks;
  hooks.on_point = [&](const cont::BranchPoint& p) {
    std::string observables;
    for (const auto& [key, value] : p.observables)
      observables += fmt::format(" {} {:.10g}", key, value);
    fmt::print("  point {:4d}{}  dim {}  |F| {:.1e}  newton {}  ds {:.3g}  {:.3f} s{}\n", p.index,
               observables, p.dimension, p.residual, p.newton_iterations, p.step_size, p.seconds,
               setup.describe_point ? "  " + setup.describe_point(p) : "");
    std::fflush(stdout);
  };
  long rejected = 0;
  hooks.reject_point = setup.reject_point;
  hooks.on_attempt = [&](const cont::StepAttempt& a) {
    if (a.rejection.empty()) return;
    ++rejected;
    fmt::print("  point {:4d}  rejected at ds {:.3g}: {}\n", a.point, a.ds, a.rejection);
  };

  const cont::SwitchingBranch result =
      cont::run_continuation(problem, setup.guess, direction, run, *corrector, hooks);
  const cont::Branch& branch = result.branch;

  const std::string summary = fmt::format(
      "problem {}\nbranch {}\nequations {}\nunknowns {}\nexpected_dimension {}\nmethod {}\n"
      "newton {}\nformulation {}\npoints {}\nrejected_corrections {}\nswitch_index {}\n"
      "stop_reason {}\nmessage {}\n",
      entry.name, branch_name, m, n, expected_dimension, cont::to_string(options.method),
      corrector->name(), periodic ? core::to_string(run.formulation) : "-", branch.points.size(),
      rejected, result.switch_index, cont::to_string(branch.reason), branch.message);
  fmt::print("stopped: {} ({})\n", cont::to_string(branch.reason), branch.message);
  if (branch.points.empty()) {
    core::write_text_atomically(out / "summary.txt", summary);
    return core::exit_numerical_failure;
  }
  const core::Table table = cont::branch_table(branch);
  table.write_csv(out / "branch.csv");
  if (periodic) cont::orbit_table(*periodic, branch).write_csv(out / "orbits.csv");
  write_figure(out, table,
               fmt::format("{} / {} ({} points)", entry.name, branch_name, branch.points.size()));
  if (setup.write_extra_outputs) setup.write_extra_outputs(out, branch);
  core::write_text_atomically(out / "summary.txt", summary);
  fmt::print("wrote {}\n", out.string());
  return core::exit_ok;
}

}  // namespace
}  // namespace backbone::drivers

static const bool registered = backbone::drivers::register_command(
    {"trace", "SCENE [--branch NAME] [--out DIR] [--key value ...]",
     "follow a nonlinear mode (branch of periodic orbits) by continuation",
     backbone::drivers::run_trace});
