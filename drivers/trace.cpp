// `backbone trace SCENE --branch NAME [--out DIR] [--key value ...]`: follows a family of
// solutions (a nonlinear mode) by continuation and writes DIR/branch.csv, DIR/orbits.csv,
// DIR/unknowns.csv, DIR/state.txt (the restart format), DIR/branch.png and DIR/summary.txt.
//
// The scene's `problem` key picks a plugin (continuation/cli/plugin.hpp); its setup builds the
// problem and the guess. Continuation settings are scene keys too (continuation/cli/
// scene_options.hpp; defaults < scene file < command line). Bad input throws core::InputError
// before anything is written (exit 2). A branch that ends before its bound or point budget keeps
// and writes its points and exits 1 (reason on stderr and in summary.txt); a run stopped by a
// signal exits 128 + the signal.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <sstream>

#include "continuation/cli/progress.hpp"
#include "continuation/cli/scene_options.hpp"
#include "continuation/cli/stop_signals.hpp"
#include "continuation/cli/trace_run.hpp"
#include "continuation/outputs.hpp"
#include "continuation/restart.hpp"
#include "core/errors.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene.hpp"
#include "core/io/scene_ini.hpp"
#include "core/io/table.hpp"
#include "core/orbits/periodic_orbit.hpp"
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
      fmt::print("  {:<14} {} (branches: {})\n", p.name, p.summary, p.branch_list());
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

// --resume DIR: the run's own resolved scene, its branch and folder in front of the other
// arguments. Returns DIR (empty without --resume).
std::filesystem::path take_resume(std::vector<std::string>& args) {
  if (args[0] != "--resume") return {};
  if (args.size() < 2) throw core::InputError("resume", "needs the folder of a traced branch");
  const std::filesystem::path resume = args[1];
  if (!std::filesystem::exists(resume / "scene.ini"))
    throw core::InputError(
        "resume", fmt::format("'{}' holds no scene.ini of a traced branch", resume.string()));
  if (!std::filesystem::exists(resume / "summary.txt"))
    throw core::InputError(
        "resume", fmt::format("'{}' holds no summary.txt of a traced branch", resume.string()));
  const std::string branch = core::read_text_value(resume / "summary.txt", "branch");
  if (cli::given_on_command_line(args, "start"))
    throw core::InputError("start",
                           "goes with a scene, not with --resume (which continues "
                           "the folder's own branch)");
  args.erase(args.begin(), args.begin() + 2);
  args.insert(args.begin(),
              {(resume / "scene.ini").string(), "--branch", branch, "--out", resume.string()});
  return resume;
}

int run_trace(const std::vector<std::string>& args_in) {
  std::vector<std::string> args = args_in;
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    print_help(nullptr);
    if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
    return core::exit_ok;
  }
  std::filesystem::path resume = take_resume(args);
  const cli::ProblemPlugin& entry = plugin_for_scene(args[0], "trace");
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (std::find_if(rest.begin(), rest.end(),
                   [](const std::string& a) { return a == "--help" || a == "-h"; }) != rest.end()) {
    print_help(&entry);
    return core::exit_ok;
  }
  // The scene file names the problem; `--problem` on the command line may only repeat it.
  if (const auto given = cli::given_on_command_line(rest, "problem"); given && *given != entry.name)
    throw core::InputError("problem", fmt::format("is the scene file's ({}); it cannot be changed "
                                                  "on the command line (got '{}')",
                                                  entry.name, *given));
  po::options_description keys = entry.scene_keys();
  keys.add(cli::continuation_keys(keys));
  cli::TraceRun t = cli::prepare_trace(entry, core::read_scene(keys, args[0], rest, driver_keys()),
                                       std::move(resume));
  cli::print_trace_header(t);

  // Output: the resolved scene first (it reproduces the run), then every point as it comes.
  cli::TraceReport report(t);
  if (t.resume.empty())
    core::write_scene_ini(t.scene, t.out / "scene.ini",
                          {"out", "help", "branch", "start", "direction"});
  core::write_text_atomically(t.out / "summary.txt", report.summary("running", nullptr, -1));

  // SIGINT / SIGTERM: stop before the next step (the point is finished and written), or at the
  // next stage after the loop; the outputs so far and the summary are written. A second one
  // stops at once (continuation/cli/stop_signals.hpp).
  std::optional<cli::StopSignals> stop(std::in_place);
  const cont::ContinuationHooks hooks = report.hooks(stop);
  cont::SwitchingBranch result =
      cli::run_continuation(t.problem(), t.setup.guess, t.direction, t.run, *t.corrector, hooks,
                            t.restart ? &*t.restart : nullptr);
  report.progress().finish();
  cli::add_saved_branch_points(t, result.branch);
  const cont::Branch& branch = result.branch;
  fmt::print("stopped: {} ({})\n", cont::to_string(branch.reason), branch.message);
  const bool followed_complete = cli::write_outputs_and_follow(t, report, branch, hooks);
  // A resumed loop may add no point (its first step reaches a bound): the branch is the files'.
  const bool complete = report.points_in_files > 0 && !branch.ended_early();
  const int stop_signal = stop->signal();
  stop.reset();  // the default actions again
  // An interrupted run's summary says so: --resume then does what it skipped.
  const char* status = stop_signal != 0 ? "interrupted" : complete ? "complete" : "ended early";
  core::write_text_atomically(t.out / "summary.txt",
                              report.summary(status, &branch, result.switch_index));
  fmt::print("wrote {}\n", t.out.string());
  if (stop_signal != 0) {
    fmt::print(stderr,
               "backbone trace: interrupted by signal {} after {} points; continue with "
               "backbone trace --resume {}\n",
               stop_signal, report.writer().points(), t.out.string());
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
          "follow a nonlinear mode (branch of periodic orbits) by continuation", run_trace};
}

}  // namespace backbone::drivers
