// What the contact-bar benchmark cases (bench_*.cpp) share besides their metrics: the mode-1
// scene, an in-process trace, timing, and the report of tables, figures and peer comparisons.
// Internal to problems/contact_bar.
//
//   const bench::PaperMode1 m = bench::paper_mode1();   // m.episode.period = 3.1
//   const double s = bench::best_seconds([&] { solver.simulate(setup, options); });
//   const bench::InProcessTrace t = bench::trace_in_process(plugin, scene, "mode1");
//   const std::vector<double> e = bench::mode1_frequency_errors(scene, t.traced.branch);
//   const auto csv = bench::write_table(table, out, "lu_legrand", 3);  // out/lu_legrand.csv
//   bench::plot(out / "lu_legrand.png", script, {1600, 700});
//   bench::report_peer_case(out, "siconos_bar", table, figure, verdict, section);
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "continuation/cli/plugin.hpp"
#include "continuation/methods/switching.hpp"
#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/bench/metrics.hpp"

namespace backbone::contact_bar::bench {

// The exact mode 1 of the paper scene (problems/contact_bar/scenes/paper.ini): L = c = EA = 1,
// g0 = 1e-3, u0 = eps x with eps = -0.01, v0 = 0; period 3.1, contact on [1.1, 2) at 0.01 N.
struct PaperMode1 {
  bar::BarSetup setup;
  double eps = 0;
  Mode1ContactEpisode episode;
};
PaperMode1 paper_mode1();

// The paper scene (problems/contact_bar/scenes/paper.ini, found wherever the binary runs) read
// with the plugin's keys and the continuation keys, as `backbone trace` reads it, with `args`
// ("--key", "value", ...) on top. Throws InputError for a bad key or value.
core::Scene read_paper_scene(const cli::ProblemPlugin& plugin,
                             const std::vector<std::string>& args);

// The median (NaN for none): the middle value, or the mean of the two middle ones.
double median(std::vector<double> values);

// One branch traced in-process as `backbone trace` traces it: the plugin's setup, the branch's
// own options (TraceSetup::apply_branch_options), the scene's formulation, corrector and
// direction, and its reject_point hook; with the CPU and wall seconds of the continuation alone.
// Throws InputError for a branch that is not a periodic-orbit problem, or kinsol on a
// non-square system.
struct InProcessTrace {
  continuation::SwitchingBranch traced;
  double cpu_seconds = 0, wall_seconds = 0;
};
InProcessTrace trace_in_process(const cli::ProblemPlugin& plugin, const core::Scene& scene,
                                const std::string& branch);

// |omega / omega_exact(E) - 1| at each point of a mode-1 branch of the scene, against the
// closed form (problems/contact_bar/orbits/README.md, 'Mode 1').
std::vector<double> mode1_frequency_errors(const core::Scene& scene,
                                           const continuation::Branch& branch);

// CPU seconds of this process (all its threads).
double process_cpu_seconds();

// Wall-clock seconds of one run.
double seconds_of(const std::function<void()>& run);
// Best of up to 3 runs; a run longer than `single` seconds is not repeated.
double best_seconds(const std::function<void()>& run, double single = 0.5);

// "  wrote PNG" or "  figure skipped: why" on stdout.
void report_plot(const core::PlotResult& result, const std::filesystem::path& png);

// Renders the gnuplot script into png (core::render_png) and reports it (report_plot).
void plot(const std::filesystem::path& png, const std::string& script, core::PlotSize size = {});

// Writes the table to out/<name>.csv, prints it aligned to `digits` significant digits, and
// returns the CSV's path.
std::filesystem::path write_table(const core::Table& table, const std::filesystem::path& out,
                                  const std::string& name, int digits = 6);

// Errors of exactly 0 (round-off luck) are drawn at this floor on the log axes.
constexpr double plot_floor = 1e-17;

// The work-precision figure of a case that puts backbone beside a peer: the rows whose first
// column is `peer_tool`, then those whose first column is `backbone_tool`, each drawn as cost
// (column x_column) against error (column y_column, 1-based, floored at plot_floor), on log
// axes.
struct PeerFigure {
  std::string xlabel, ylabel, title;
  int x_column = 0, y_column = 0;
  std::string peer_tool, peer_title;
  std::string backbone_tool, backbone_title;
};
// The gnuplot script of that figure, reading csv.
std::string peer_figure_script(const std::filesystem::path& csv, const PeerFigure& figure);

// What a peer case reports once its table is complete: out/<name>.csv, written and printed
// with 3 significant digits; out/<name>.png, the figure; the verdict on stdout; and the
// BENCHMARKS.md section <name>.md (cli::write_bench_section).
void report_peer_case(const std::filesystem::path& out, const std::string& name,
                      const core::Table& table, const PeerFigure& figure,
                      const std::string& verdict, const std::string& section);

}  // namespace backbone::contact_bar::bench
