// What the contact-bar benchmark cases (bench_*.cpp) share besides their metrics: the mode-1
// scene, an in-process trace, timing and figure reporting. Internal to problems/contact_bar.
//
//   const bench::PaperMode1 m = bench::paper_mode1();   // m.episode.period = 3.1
//   const double s = bench::best_seconds([&] { solver.simulate(setup, options); });
//   const bench::InProcessTrace t = bench::trace_in_process(plugin, scene, "mode1");
//   const std::vector<double> e = bench::mode1_frequency_errors(scene, t.traced.branch);
//   bench::report_plot(core::render_png(png, script), png);
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "continuation/cli/plugin.hpp"
#include "continuation/switching.hpp"
#include "core/plot.hpp"
#include "core/scene.hpp"
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
// closed form (problems/contact_bar/README.md, 'Mode 1').
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

}  // namespace backbone::contact_bar::bench
