// A trace as `backbone trace` runs it, in named steps: prepare_trace reads and checks every
// setting and builds the problem (and takes up a restart) before anything is written; a
// TraceReport writes each accepted point into the branch files and a line on the screen, counts
// rejected steps and writes summary.txt; write_outputs_and_follow draws the branch, writes the
// problem's extra outputs and follows the attached branches.
//
//   TraceRun t = prepare_trace(plugin, scene, /*resume=*/{});   // InputError on bad input
//   print_trace_header(t);
//   TraceReport report(t);                                      // creates t.out's files
//   std::optional<StopSignals> stop(std::in_place);
//   const auto hooks = report.hooks(stop);
//   auto result = run_continuation(t.problem(), t.setup.guess, t.direction, t.run,
//                                  *t.corrector, hooks, t.restart ? &*t.restart : nullptr);
//   write_outputs_and_follow(t, report, result.branch, hooks);
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "continuation/cli/plugin.hpp"
#include "continuation/cli/progress.hpp"
#include "continuation/cli/scene_options.hpp"
#include "continuation/cli/stop_signals.hpp"
#include "continuation/outputs.hpp"
#include "continuation/restart.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "core/orbits/periodic_orbit.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::cli {

// Everything a trace needs, read and checked before anything is written.
struct TraceRun {
  const ProblemPlugin* entry = nullptr;
  std::filesystem::path resume;  // the folder of `trace --resume DIR`, else empty
  core::Scene scene;             // the problem's keys, the continuation keys and trace's own
  std::string branch_name;
  std::filesystem::path out;
  RunSettings run;
  TraceSetup setup;
  std::unique_ptr<core::Corrector> corrector, follow_corrector;
  core::PeriodicOrbitProblem* periodic = nullptr;  // setup.problem when it is one
  core::Vector direction;                          // the first tangent's hint
  std::optional<continuation::RestartPoint> restart;
  // A resumed detecting run: the candidates located before its restart point (branch_points.txt,
  // continuation::branch_point_resume), and the last complete point of the files when the
  // restart point lies before it (the points after it are traced again), else -1.
  std::optional<continuation::SavedBranchPoints> saved_branch_points;
  int resume_drops_after = -1;
  int expected_dimension = 0;
  // One writer of `out` at a time: taken before a resume repairs the saved files, else by
  // TraceReport once every check has passed.
  std::unique_ptr<core::FolderLock> lock;

  const core::Problem& problem() const { return *setup.problem; }
  continuation::ContinuationOptions& options() { return run.options; }
};

// The branch (scene key `branch`, default the plugin's first), the output folder (`out`,
// default out/PROBLEM_BRANCH), the settings and the problem; with `resume` or the key `start` a
// restart takes up its saved point (its loop state, or its unknowns, the way the branch went,
// the next step; `direction` +1 or -1) and numbers on from it. Throws core::InputError naming
// the key for bad input.
TraceRun prepare_trace(const ProblemPlugin& entry, core::Scene scene, std::filesystem::path resume);

// The run's first lines: equations, unknowns, expected dimension, method and step settings.
void print_trace_header(TraceRun& t);

// What the run reports as it goes: every point into the branch files (BranchWriter; after a
// resume, appended) and a line on the screen, the located branch points, the rejected steps,
// and summary.txt (summary()). It takes the lock of t.out (TraceRun::lock) when the run does
// not hold it yet: a second run into the same folder is refused before it writes anything.
class TraceReport {
 public:
  explicit TraceReport(TraceRun& t);

  std::size_t points_in_files = 0;  // the whole branch, a resumed run's saved points included
  continuation::BranchWriter& writer() { return writer_; }
  ProgressLine& progress() { return progress_; }

  // stop: the signal handlers while they are installed (the whole run, the stages after the
  // loop and the followed branches too).
  continuation::ContinuationHooks hooks(const std::optional<StopSignals>& stop);
  // summary.txt: `key value` lines (problem, branch, status, counts, stop reason, ...).
  std::string summary(const std::string& status, const continuation::Branch* branch,
                      int switch_index) const;
  // The summary's counts from the whole branch.csv (its dimension and dimension_flag columns,
  // and stable when the points have multipliers), so that a resumed run counts the points it did
  // not correct itself.
  void count_points(const core::Table& branch_csv);
  // The summary's located and verified branch points: the rows of branch_points.csv.
  void count_branch_points(const core::Table& branch_points_csv);

 private:
  void on_point(const continuation::BranchPoint& p);

  TraceRun& t_;
  continuation::BranchWriter writer_;
  // With detection: every candidate located so far (the saved ones of a resume first), kept in
  // t.out/branch_points.txt as they come.
  continuation::SavedBranchPoints located_;
  bool keep_list_ = false;  // located_ is kept in branch_points.txt
  ProgressLine progress_;
  long dimension_flags_[3] = {0, 0, 0};  // branch.csv points per DimensionFlag (branch.hpp)
  long dimension_above_ = 0;             // points verified above the expected dimension
  int last_dimension_ = -1;              // the last point's verified dimension (-1: none yet)
  std::string stability_;                // stability_counts of branch.csv (empty: not yet)
  long branch_points_[2] = {-1, -1};     // located, verified (-1: no detection)
};

// After the run: the number of located branch points, the figure and the extra outputs of the
// whole branch (saved points included), then the followed branches. Returns whether every
// followed branch reached its bound or budget (false too when `--follow K` names a row the
// run did not locate). A stop request (hooks.cancel_requested) skips the stages not begun:
// the problem's outputs over the branch, the stability report and the follows. It sets
// report.points_in_files (branch.csv's rows), on which the run's verdict rests: a resumed
// loop that added no point (its first step reached a bound) stands on the saved points.
bool write_outputs_and_follow(TraceRun& t, TraceReport& report, const continuation::Branch& traced,
                              const continuation::ContinuationHooks& hooks);

// A resumed detecting run's branch holds the candidates it located; the saved ones located
// before its restart point go in front, so that branch_points.csv, the rows K of --follow K and
// the followed branches cover the whole branch.
void add_saved_branch_points(const TraceRun& t, continuation::Branch& branch);

}  // namespace backbone::cli
