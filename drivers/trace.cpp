// `backbone trace SCENE --branch NAME [--out DIR] [--key value ...]`: follows a family of
// solutions (a nonlinear mode) by continuation and writes DIR/branch.csv, DIR/orbits.csv,
// DIR/unknowns.csv, DIR/state.txt (the restart format), DIR/branch.png and DIR/summary.txt.
//
// The scene's `problem` key picks a plugin (continuation/cli/plugin.hpp); its setup builds the
// problem and the guess. Continuation settings are scene keys too (continuation/
// scene_options.hpp; defaults < scene file < command line). Bad input throws core::InputError
// before anything is written (exit 2). A branch that ends early keeps and writes its points
// (exit 0, reason printed and in summary.txt); exit 1 only when no point converged.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <sstream>

#include "continuation/outputs.hpp"
#include "continuation/cli/progress.hpp"
#include "continuation/restart.hpp"
#include "continuation/cli/scene_options.hpp"
#include "continuation/cli/stop_signals.hpp"
#include "core/errors.hpp"
#include "core/output_folder.hpp"
#include "core/periodic_orbit.hpp"
#include "core/scene.hpp"
#include "core/scene_ini.hpp"
#include "core/table.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace backbone::drivers {
namespace {

namespace po = boost::program_options;
namespace cont = backbone::continuation;

po::options_description driver_keys() {
  po::options_description keys("trace");
  keys.add_options()                                                                             //
      ("branch", po::value<std::string>(), "branch to follow (the problem lists its branches)")  //
      ("out", po::value<std::string>(), "output directory (default out/PROBLEM_BRANCH)")         //
      ("start", po::value<std::string>(),
       "DIR:K (or DIR/orbits.csv:K): start from point K of a traced branch (its saved loop "
       "state, state.txt: the rest of that branch bit for bit)")  //
      ("direction", po::value<long>()->default_value(1),
       "with --start: +1 continues the saved branch's way, -1 goes back")  //
      ("help", "describe the command, the problem's keys and the continuation keys");
  return keys;
}

void print_help(const cli::ProblemPlugin* problem) {
  fmt::print(
      "usage: backbone trace SCENE [--branch NAME] [--out DIR] [--start DIR:K] [--key value ...]\n"
      "       backbone trace --resume DIR [--key value ...]   (continue an interrupted run)\n\n");
  fmt::print("problems (scene key `problem`):\n");
  for (const auto& p : plugins().all())
    if (p.can_trace())
      fmt::print("  {:<14} {} (branches: {})\n", p.name, p.summary, fmt::join(p.branches, ", "));
  std::ostringstream text;
  text << "\n" << driver_keys() << "\n";
  if (problem) {
    const po::options_description keys = problem->scene_keys();
    text << keys << "\n" << cli::continuation_keys(keys);
  } else {
    text << cli::continuation_keys(po::options_description())
         << "\n(defaults of a problem's own keys: backbone trace SCENE --help)\n";
  }
  fmt::print("{}\n", text.str());
}

int run_trace(const std::vector<std::string>& args_in) {
  std::vector<std::string> args = args_in;
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    print_help(nullptr);
    if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
    return core::exit_ok;
  }
  // --resume DIR: the run's own resolved scene, its branch and folder.
  std::filesystem::path resume;
  if (args[0] == "--resume") {
    if (args.size() < 2) throw core::InputError("resume", "needs the folder of a traced branch");
    resume = args[1];
    if (!std::filesystem::exists(resume / "scene.ini"))
      throw core::InputError(
          "resume", fmt::format("'{}' holds no scene.ini of a traced branch", resume.string()));
    const std::string branch = core::read_text_value(resume / "summary.txt", "branch");
    args.erase(args.begin(), args.begin() + 2);
    args.insert(args.begin(),
                {(resume / "scene.ini").string(), "--branch", branch, "--out", resume.string()});
  }
  const std::string scene_path = args[0];
  const cli::ProblemPlugin& entry = plugin_for_scene(scene_path, "trace");
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (std::find_if(rest.begin(), rest.end(),
                   [](const std::string& a) { return a == "--help" || a == "-h"; }) != rest.end()) {
    print_help(&entry);
    return core::exit_ok;
  }

  po::options_description keys = entry.scene_keys();
  keys.add(cli::continuation_keys(keys));
  const core::Scene scene = core::read_scene(keys, scene_path, rest, driver_keys());
  const std::string branch_name = scene.has("branch") ? scene.text("branch") : entry.branches.at(0);
  if (std::find(entry.branches.begin(), entry.branches.end(), branch_name) == entry.branches.end())
    throw core::InputError(
        "branch", fmt::format("'{}' is not a branch of {} (known: {})", branch_name, entry.name,
                              fmt::join(entry.branches, ", ")));
  const std::filesystem::path out =
      scene.has("out") ? scene.text("out") : fmt::format("out/{}_{}", entry.name, branch_name);
  core::check_output_folder("out", out);
  cli::RunSettings run = cli::read_run_settings(scene);
  cont::ContinuationOptions& options = run.options;
  const long start_direction = scene.integer("direction", -1);
  if (start_direction != 1 && start_direction != -1)
    throw core::InputError("direction", fmt::format("must be 1 or -1 (got {})", start_direction));

  cli::TraceSetup setup = entry.setup(scene, branch_name);
  if (!setup.problem) throw core::InputError("problem", "setup returned no problem");
  const core::Problem& problem = *setup.problem;
  setup.apply_branch_options(options, run.newton_options);
  auto corrector = core::make_corrector(run.newton, run.newton_options);
  auto follow_corrector =
      core::make_corrector(run.newton, cont::follow_newton_options(run.newton_options, options));
  auto* periodic = dynamic_cast<core::PeriodicOrbitProblem*>(setup.problem.get());
  if (periodic) periodic->set_formulation(run.formulation);
  core::Vector direction = setup.direction;
  if (direction.size() == 0)
    direction = core::Vector::Unit(
        problem.num_unknowns(), periodic ? periodic->period_index() : problem.num_unknowns() - 1);

  // A restart takes up a saved point: its loop state (or its unknowns, the way the branch went,
  // the next step), and numbers on from it.
  std::optional<cont::RestartPoint> restart;
  const std::string restart_key = resume.empty() ? "start" : "resume";
  if (!resume.empty()) {
    cont::repair_branch_files(resume, "resume");
    restart = cont::restart_point(resume, -1, options, "resume");
    restart->record_saved_point = false;  // it is in the files
  } else if (scene.has("start")) {
    const auto [dir, point] = cont::parse_saved_point(scene.text("start"), "start");
    restart = cont::restart_point(dir, point, options, "start");
  }
  if (restart)
    cont::take_up(*restart, restart_key, static_cast<int>(start_direction), problem, options,
                  setup.guess, direction);

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
  fmt::print("  {} continuation, {} predictor, newton {}, {}{}{}\n",
             cont::to_string(options.method), cont::to_string(options.predictor), corrector->name(),
             periodic ? fmt::format("formulation {}, ", core::scene_name(run.formulation)) : "",
             fmt::format("ds {:g} in [{:g}, {:g}], at most {} points", options.ds, options.ds_min,
                         options.ds_max, options.max_points),
             restart ? fmt::format(", restarting from point {} ({})", restart->index,
                                   restart->state ? "its saved loop state"
                                                  : "corrected again: " + (restart->note.empty()
                                                                               ? "no saved state"
                                                                               : restart->note))
                     : "");

  // Output: the resolved scene first (it reproduces the run), then every point as it comes.
  std::size_t points_in_files = 0;      // the whole branch, a resumed run's saved points included
  long dimension_flags[3] = {0, 0, 0};  // points per DimensionFlag (branch.hpp)
  const auto summary = [&](const std::string& status, const cont::Branch* branch, long rejected,
                           int switch_index) {
    return fmt::format(
        "problem {}\nbranch {}\nstatus {}\nequations {}\nunknowns {}\nexpected_dimension {}\n"
        "method {}\nnewton {}\nformulation {}\npoints {}\nrejected_corrections {}\n"
        "switch_index {}\nstop_reason {}\nmessage {}\ndimension_rechecked {}\n"
        "dimension_unconfirmed {}\n",
        entry.name, branch_name, status, m, n, expected_dimension, cont::to_string(options.method),
        corrector->name(), periodic ? core::scene_name(run.formulation) : "-", points_in_files,
        rejected, switch_index, branch ? cont::to_string(branch->reason) : "-",
        branch ? branch->message : "-", dimension_flags[1], dimension_flags[2]);
  };
  cont::BranchWriter writer(out, periodic, restart.has_value() && !resume.empty());
  if (resume.empty())
    core::write_scene_ini(scene, out / "scene.ini",
                          {"out", "help", "branch", "start", "direction"});
  core::write_text_atomically(out / "summary.txt", summary("running", nullptr, 0, -1));

  // SIGINT / SIGTERM: stop before the next step (the point is finished and written, then the
  // summary); a second one stops at once (continuation/cli/stop_signals.hpp).
  std::optional<cli::StopSignals> stop(std::in_place);
  cli::ProgressLine progress(options);
  cont::ContinuationHooks hooks;
  hooks.cancel_requested = [&] { return stop->requested(); };
  hooks.on_point = [&](const cont::BranchPoint& p_in) {
    if (restart && !resume.empty() && p_in.index == restart->index) return;  // in the files
    const cont::BranchPoint& p = p_in;
    writer.append(p);
    if (p.dimension_flag != cont::DimensionFlag::as_verified)
      fmt::print(stderr, "backbone trace: point {}: {}\n", p.index, cont::dimension_warning(p));
    dimension_flags[static_cast<int>(p.dimension_flag)] += 1;
    progress.finish();  // the point's line replaces the progress line, which follows it
    fmt::print("  {}{}\n", cli::point_line(p),
               setup.describe_point ? "  " + setup.describe_point(p) : "");
    std::fflush(stdout);
    progress.update(p);
  };
  long rejected = 0;
  hooks.reject_point = setup.reject_point;
  hooks.describe_branch_point = setup.describe_branch_point;
  // Located candidates as they come (from the detector's thread, a few points after the bracket
  // that holds them; continuation/README.md, 'Branch points'), between the point lines.
  hooks.on_branch_point = [&](const cont::BranchPointReport& r) {
    progress.finish();
    fmt::print("  {}\n", cli::branch_point_line(r));
    std::fflush(stdout);
  };
  hooks.on_attempt = [&](const cont::StepAttempt& a) {
    if (a.rejection.empty()) return;
    ++rejected;
    fmt::print("  point {:4d}  rejected at ds {:.3g}: {}\n", a.point, a.ds, a.rejection);
  };

  cont::SwitchingBranch result = cli::run_continuation(
      problem, setup.guess, direction, run, *corrector, hooks, restart ? &*restart : nullptr);
  const int stop_signal = stop->signal();
  stop.reset();  // the default actions again
  progress.finish();
  cont::Branch& branch = result.branch;
  const bool complete = !branch.points.empty() && !branch.ended_early();
  bool followed_complete = true;  // every followed branch reached its bound or budget
  fmt::print("stopped: {} ({})\n", cont::to_string(branch.reason), branch.message);
  if (options.branch_points.detect) {
    const auto verified = std::count_if(branch.branch_points.begin(), branch.branch_points.end(),
                                        [](const cont::BranchPointReport& r) { return r.verified(); });
    fmt::print("branch points located by this run: {} ({} verified; branch_points.csv)\n",
               branch.branch_points.size(), verified);
  }
  if (!branch.points.empty()) {
    // The figure and the extra outputs show the whole branch, saved points included.
    const core::Table table = core::Table::read_csv(out / "branch.csv");
    points_in_files = table.rows();
    cont::plot_branch(out, table,
                      fmt::format("{} / {} ({} points)", entry.name, branch_name, table.rows()),
                      entry.units);
    cont::write_after_run(out, problem, branch, !resume.empty(), options.branch_points.detect,
                          setup.write_extra_outputs);
    for (const auto& f :
         cont::follow_branch_points(problem, branch, run.follow, *follow_corrector, options, hooks,
                                    out, setup.write_extra_outputs, entry.units)) {
      fmt::print("  followed {}\n", cont::follow_line(f));
      followed_complete = followed_complete && !f.branch.points.empty() && !f.branch.ended_early();
    }
  }
  core::write_text_atomically(out / "summary.txt", summary(complete ? "complete" : "ended early",
                                                           &branch, rejected, result.switch_index));
  fmt::print("wrote {}\n", out.string());
  if (stop_signal != 0) {
    fmt::print(stderr,
               "backbone trace: interrupted by signal {} after {} points; continue with "
               "backbone trace --resume {}\n",
               stop_signal, writer.points(), out.string());
    return 128 + stop_signal;
  }
  if (!complete || !followed_complete) {
    fmt::print(stderr, "backbone trace: {} ended before its bound or point budget{}\n",
               complete ? "a followed branch (lines 'followed' above)" : "the branch",
               complete ? "" : ": " + branch.message);
    return core::exit_numerical_failure;
  }
  return core::exit_ok;
}

}  // namespace
}  // namespace backbone::drivers

namespace backbone::drivers {

Command trace_command() {
  return {"trace", "SCENE [--branch NAME] [--out DIR] [--key value ...]",
     "follow a nonlinear mode (branch of periodic orbits) by continuation",
     run_trace};
}

}  // namespace backbone::drivers
