// What the contact-bar benchmark cases (bench_*.cpp) share besides their metrics: the mode-1
// scene, timing and figure reporting. Internal to problems/contact_bar.
//
//   const bench::PaperMode1 m = bench::paper_mode1();   // m.episode.period = 3.1
//   const double s = bench::best_seconds([&] { solver.simulate(setup, options); });
//   bench::report_plot(core::render_png(png, script), png);
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "core/plot.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/bench_metrics.hpp"

namespace backbone::contact_bar::bench {

// The exact mode 1 of the paper scene (problems/contact_bar/scenes/paper.ini): L = c = EA = 1,
// g0 = 1e-3, u0 = eps x with eps = -0.01, v0 = 0; period 3.1, contact on [1.1, 2) at 0.01 N.
struct PaperMode1 {
  bar::BarSetup setup;
  double eps = 0;
  Mode1ContactEpisode episode;
};
PaperMode1 paper_mode1();

// The median (NaN for none): the middle value, or the mean of the two middle ones.
double median(std::vector<double> values);

// Wall-clock seconds of one run.
double seconds_of(const std::function<void()>& run);
// Best of up to 3 runs; a run longer than `single` seconds is not repeated.
double best_seconds(const std::function<void()>& run, double single = 0.5);

// "  wrote PNG" or "  figure skipped: why" on stdout.
void report_plot(const core::PlotResult& result, const std::filesystem::path& png);

}  // namespace backbone::contact_bar::bench
