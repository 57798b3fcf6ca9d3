// The files a traced branch is written to, point by point, so that an interrupted run keeps
// every completed point.
//
// BranchWriter appends each accepted point, as soon as it is accepted, to
//   branch.csv    the columns of branch_table (branch.hpp): observables, dimension, cost
//   orbits.csv    `point,x,u0`: the initial state of the orbit as (coordinate, value) samples
//                 (core::PeriodicOrbitProblem::initial_state_samples), for figures
//   unknowns.csv  `point,index,value`: the point's unknowns x in the problem's own layout
//                 (read_unknowns)
//   multipliers.csv  `point,index,re,im,modulus,trivial`: the orbit's Floquet multipliers
//                 (branch.hpp, multiplier_table), when the points carry them
//   state.txt     `point state`: the loop's state after the point (restart.hpp, format_state;
//                 `-` when the loop could not go on from it), what `trace --resume DIR` and
//                 `--start DIR:K` continue from bit for bit (without it they correct the
//                 unknowns again)
// and flushes them, so even SIGKILL leaves readable files holding every completed point. A
// row is written with one call, so at worst the last line is cut (read_csv refuses a short
// row; remove it or resume, which rewrites the files).
//
//   BranchWriter writer(out, periodic_or_null);
//   hooks.on_point = [&](const BranchPoint& p) { writer.append(p); };
//   ... continuation ...
//   core::Vector x = read_unknowns(out / "unknowns.csv", /*point=*/-1, "resume");  // the last
#pragma once

#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "continuation/branch.hpp"
#include "continuation/options.hpp"
#include "continuation/restart.hpp"  // parse_saved_point, restart_point: the restart format
#include "core/io/table.hpp"
#include "core/orbits/periodic_orbit.hpp"

namespace backbone::continuation {

core::Table orbit_table(const core::PeriodicOrbitProblem& problem, const Branch& branch);

// out/branch.png from the rows of out/branch.csv (`table`), every point: `axes` (x, y columns)
// when the table has both, else frequency against energy (log axis) when the problem reports
// them, else the first two observables; axis labels carry the units the problem gives
// (ProblemPlugin::units). With a `stable` column the line is solid where the orbits are stable,
// dashed where unstable, dotted where undecided. A figure that cannot be drawn (no gnuplot) is
// reported on stderr, not an error. branch_plot_script is its gnuplot text (empty when the
// table has too few columns).
void plot_branch(const std::filesystem::path& out, const core::Table& table,
                 const std::string& title, const std::map<std::string, std::string>& units = {},
                 const std::pair<std::string, std::string>& axes = {});
std::string branch_plot_script(const std::filesystem::path& csv, const core::Table& table,
                               const std::string& title,
                               const std::map<std::string, std::string>& units = {},
                               const std::pair<std::string, std::string>& axes = {});

// Gnuplot data blocks $<prefix>stable, $<prefix>unstable and $<prefix>undecided
// (comma-separated, as core::render_png reads, each with a header line): the segments of a
// branch table's (x, y) columns by the `stable` column of their points, each run of one kind
// drawn through the first point of the next run, so that the line is unbroken where the kind
// changes; a block without segments holds one NaN point. The table must have a stable column.
std::string stability_datablocks(const core::Table& table, const std::string& x,
                                 const std::string& y, const std::string& prefix);

// summary.txt's stability lines: the points of a branch table by its `stable` column,
// "stable_points N\nunstable_points N\nundecided_points N\n", each "-" without a table or when
// it has no such column (no multipliers).
std::string stability_counts(const core::Table* table);

class BranchWriter {
 public:
  // Creates `out` (and its parents). periodic: the problem when it is a periodic-orbit problem
  // (orbits.csv is written only then), else nullptr. append = false truncates existing files;
  // true appends to them (after repair_branch_files).
  BranchWriter(std::filesystem::path out, const core::PeriodicOrbitProblem* periodic,
               bool append = false);
  ~BranchWriter();
  BranchWriter(const BranchWriter&) = delete;
  BranchWriter& operator=(const BranchWriter&) = delete;
  // Appends the point to every file and flushes them. Throws std::runtime_error when a file
  // cannot be written.
  void append(const BranchPoint& point);
  int points() const { return points_; }

 private:
  struct File;
  std::filesystem::path out_;
  const core::PeriodicOrbitProblem* periodic_;
  std::unique_ptr<File> branch_, orbits_, unknowns_, multipliers_, state_;
  int points_ = 0;
};

// Checks, reading only, that the files of a traced branch in `dir` are what BranchWriter
// writes: each present file has its header, and every complete line (a last line cut by an
// interruption is allowed) is a row of numbers with the header's count of cells (state.txt: a
// point index, then a state or `-`). InputError naming `key` and the file and line otherwise,
// before a resume repairs anything or a start reads a point.
void check_saved_files(const std::filesystem::path& dir, const std::string& key);

// Makes the files of an interrupted run consistent: drops a line cut by the interruption and
// every row of a point that is not complete in all of branch.csv, unknowns.csv (and orbits.csv
// and state.txt when present). Returns the last complete point; InputError naming `key` when there
// is none.
// up_to: also drops the points after it (a resume that takes up an earlier point).
int repair_branch_files(const std::filesystem::path& out, const std::string& key,
                        int up_to = std::numeric_limits<int>::max());

// Replaces the saved loop state of every point of out/state.txt by `-` (none), atomically: what
// a resume does when the saved states do not fit its settings (restart.hpp, state_mismatch), so
// that the folder holds no states of another run's loop. Nothing when there is no state.txt.
void forget_saved_states(const std::filesystem::path& out);

// The unknowns of point `point` (-1: the last one) of an unknowns.csv. InputError naming `key`
// when the file cannot be read or has no such point.
core::Vector read_unknowns(const std::filesystem::path& path, int point, const std::string& key);

// The saved points up to resumed's first (dir/unknowns.csv, their observables recomputed, and
// their multipliers with floquet non-null), then resumed's later ones: the whole branch as the
// files of a resumed run hold it (every saved point when the resumed loop added none). The restart
// point is the saved one: a restart without a saved loop state corrects it again, to other
// round-off, and branch.csv keeps the saved row.
Branch whole_branch(const std::filesystem::path& dir, const core::Problem& problem,
                    const Branch& resumed, const core::FloquetOptions* floquet);

// What trace writes after the run: the problem's extra outputs (`extra`) and, with `detect`,
// branch_points.csv. After a resume (`resumed`) the branch holds only the resumed points; both
// then cover the whole branch as its files hold it: the saved points before the first resumed
// one are read back from out/unknowns.csv (observables recomputed, rank fields unset), and the
// saved rows of branch_points.csv located before it are kept.
void write_after_run(const std::filesystem::path& out, const core::Problem& problem,
                     const Branch& branch, bool resumed, bool detect,
                     const std::function<void(const std::filesystem::path&, const Branch&)>& extra);

}  // namespace backbone::continuation
