// Benchmarks lu_legrand and siconos_bar (bench_peers.hpp): backbone beside its stored peers.
#include "problems/contact_bar/bench/peers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>

#include "continuation/cli/bench_report.hpp"
#include "core/errors.hpp"
#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "problems/contact_bar/bench/support.hpp"
#include "problems/contact_bar/cli/trace.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/solver/scene.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_solution.hpp"

#ifndef BACKBONE_CONTACT_BAR_DIR
#define BACKBONE_CONTACT_BAR_DIR "problems/contact_bar"
#endif

namespace backbone::contact_bar {

namespace {

constexpr int repetitions = 3;  // medians of 3, as the stored peer runs

std::filesystem::path contact_bar_folder() {
  const std::filesystem::path built_in = BACKBONE_CONTACT_BAR_DIR;
  if (std::filesystem::exists(built_in / "scenes" / "paper.ini")) return built_in;
  return "problems/contact_bar";  // a moved source tree: relative to the repository root
}

// Compute seconds of a run: the process CPU time on one thread, since the peers' figures are of
// an otherwise idle core and a shared machine's load inflates wall time but not CPU time; with
// `bench --threads K > 1` the wall time, which is what threads shorten.
class Stopwatch {
 public:
  Stopwatch() : wall_(std::chrono::steady_clock::now()), cpu_(cpu_now()) {}
  double seconds() const {
    if (core::default_jacobian_threads() > 1)
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_).count();
    return cpu_now() - cpu_;
  }

 private:
  static double cpu_now() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  }
  std::chrono::steady_clock::time_point wall_;
  double cpu_;
};

std::string clock_name() {
  const int threads = core::default_jacobian_threads();
  return threads > 1 ? fmt::format("wall time with {} threads", threads)
                     : std::string("CPU time of one thread");
}

}  // namespace

std::filesystem::path contact_bar_peers_folder() {
  return contact_bar_folder() / "bench" / "peers";
}

Mode1Trace trace_paper_mode1(int shooting_elements) {
  const cli::ProblemPlugin plugin = trace_plugin();
  const core::Scene scene = bench::read_paper_scene(
      plugin, {"--start_offset", "0.25", "--energy_max", "5e-3", "--shooting_elements",
               std::to_string(shooting_elements), "--threads",
               std::to_string(core::default_jacobian_threads())});  // bench --threads K
  const bench::InProcessTrace run = bench::trace_in_process(plugin, scene, "mode1");
  Mode1Trace t;
  // As Stopwatch: CPU time on one thread, wall time with `bench --threads K > 1`.
  t.seconds = core::default_jacobian_threads() > 1 ? run.wall_seconds : run.cpu_seconds;
  const continuation::Branch& branch = run.traced.branch;
  t.elements = shooting_elements;
  t.points = static_cast<int>(branch.points.size());
  t.message = branch.message;
  t.complete = branch.reason == continuation::StopReason::bound_reached;
  const std::vector<double> errors = bench::mode1_frequency_errors(scene, branch);
  t.median_error = bench::median(errors);
  t.max_error = errors.empty() ? std::nan("") : *std::max_element(errors.begin(), errors.end());
  return t;
}

namespace {

// Lu & Legrand's stored runs: one per harmonic count, the errors over their admissible points.
struct LuLegrandRun {
  int harmonics;
  int points;
  double seconds, ms, median, max;
};

std::vector<LuLegrandRun> read_lu_legrand_runs() {
  const std::filesystem::path peers = contact_bar_peers_folder();
  const core::Table runs = core::Table::read_csv(peers / "lu_legrand_runs.csv");
  std::vector<LuLegrandRun> stored;
  for (std::size_t i = 0; i < runs.rows(); ++i) {
    const int harmonics = static_cast<int>(runs.column("harmonics")[i]);
    const core::Table points =
        core::Table::read_csv(peers / fmt::format("lu_legrand_mode1_h{}.csv", harmonics));
    std::vector<double> errors;  // their own rule: admissible points only
    const std::vector<double> admissible = points.column("admissible"),
                              error = points.column("relerr_freq");
    for (std::size_t j = 0; j < points.rows(); ++j)
      if (admissible[j] == 1) errors.push_back(error[j]);
    stored.push_back({harmonics, static_cast<int>(points.rows()), runs.column("seconds")[i],
                      runs.column("ms_per_point")[i], bench::median(errors),
                      *std::max_element(errors.begin(), errors.end())});
  }
  return stored;
}

// backbone's mode-1 trace at each grid, timed at the median of `repetitions` runs (one for a
// grid slower than 5 s); status 1 when a trace stops early.
std::vector<Mode1Trace> trace_lu_legrand_grids(int& status) {
  std::vector<Mode1Trace> traces;
  for (int elements : {10, 20, 40}) {
    std::vector<double> seconds;
    Mode1Trace t;
    for (int k = 0; k < repetitions; ++k) {
      t = trace_paper_mode1(elements);
      seconds.push_back(t.seconds);
      if (t.seconds > 5) break;  // one run of a slow grid is enough
    }
    t.seconds = bench::median(seconds);
    if (!t.complete) {
      fmt::print("  warning: N = {} stopped early: {}\n", elements, t.message);
      status = 1;
    }
    traces.push_back(t);
  }
  return traces;
}

core::Table lu_legrand_table(const std::vector<LuLegrandRun>& stored,
                             const std::vector<Mode1Trace>& traces) {
  core::Table table({"tool", "setting", "points", "seconds", "ms_per_point", "median_error",
                     "max_error", "live"});
  for (const LuLegrandRun& r : stored)
    table.add_cells({std::string("lu_legrand"), fmt::format("{} harmonics", r.harmonics),
                     double(r.points), r.seconds, r.ms, r.median, r.max, 0.0});
  for (const Mode1Trace& t : traces)
    table.add_cells({std::string("backbone"), fmt::format("N = {}", t.elements), double(t.points),
                     t.seconds, 1e3 * t.seconds / t.points, t.median_error, t.max_error, 1.0});
  return table;
}

std::string lu_legrand_section(const std::vector<LuLegrandRun>& stored,
                               const std::vector<Mode1Trace>& traces, const std::string& verdict) {
  std::string rows;
  for (const LuLegrandRun& r : stored)
    rows +=
        fmt::format("| Lu & Legrand (stored) | {} harmonics | {} | {:.3g} | {:.2g} | {:.2g} |\n",
                    r.harmonics, r.points, r.ms, r.median, r.max);
  for (const Mode1Trace& t : traces)
    rows += fmt::format("| backbone | N = {} | {} | {:.3g} | {:.2g} | {:.2g} |\n", t.elements,
                        t.points, 1e3 * t.seconds / t.points, t.median_error, t.max_error);
  return fmt::format(
      "## Mode 1 of the contact bar: backbone vs Lu & Legrand (`lu_legrand`)\n\n"
      "Mode 1 of the paper scene from T = 3.8 to 3.01 (E = 7.8e-7 to 5e-3 J; Lu & Legrand's "
      "g0 = 0.5 run covers the same range of E / g0^2). backbone: `trace "
      "problems/contact_bar/scenes/paper.ini --branch mode1 --start_offset 0.25 "
      "--energy_max 5e-3 --shooting_elements N`, run in-process, {}, median of {} runs "
      "(one when it takes over 5 s). Lu & Legrand: their stored runs "
      "(problems/contact_bar/bench/peers/, "
      "measured on the same kind of machine; not run here), errors over their admissible "
      "points. Error: |omega / omega_exact(E) - 1| with the mode-1 closed form at each "
      "point's own energy, for both.\n\n"
      "| tool | setting | points | ms/point | median error | max error |\n"
      "|---|---|---|---|---|---|\n{}\n"
      "**Where backbone stands:** {}\n\n![Mode 1 vs Lu & Legrand](lu_legrand.png)\n",
      clock_name(), repetitions, rows, verdict);
}

// The Siconos bar: mode 1 with eps = -0.002 (T = 3.5) over 10 time units at dt = 1e-3.
struct SiconosBar {
  double eps = -0.002, gap = 1e-3, t_end = 10, dt = 1e-3;
  bar::BarSetup setup;
  double amplitude = 0;  // |eps| L: the tip error's unit
  long steps = 0;
  SiconosBar() {
    setup.left = {bar::EndType::fixed, 0};
    setup.right = {bar::EndType::contact, gap};
    setup.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, eps});
    amplitude = std::abs(eps) * setup.material.length;
    steps = std::lround(t_end / dt);
  }
};

// One TD-BEM march of the Siconos bar: us per step, max tip error / amplitude, energy change.
struct SiconosRow {
  int elements;
  double us, error, energy;
};

SiconosRow march_siconos_bar(const SiconosBar& b, const exact_bar::ExactBarSolution& exact,
                             int elements, int& status) {
  const TdbemSolver tdbem(ContactMethod::event);
  bar::SimulationOptions o;
  o.t_end = b.t_end;
  o.dt = b.dt;
  o.elements = elements;
  o.history_samples = static_cast<int>(b.steps) + 2;  // every step: the tip error
  o.energy = false;                                   // the bare march is timed
  bar::History h;
  std::vector<double> seconds;
  for (int k = 0; k < repetitions; ++k) {
    const Stopwatch stopwatch;
    h = tdbem.simulate(b.setup, o);
    seconds.push_back(stopwatch.seconds());
  }
  double error = 0;
  for (std::size_t j = 0; j < h.t.size(); ++j)
    error = std::max(error, std::abs(h.u_contact[j] - exact.u_end(h.t[j])) / b.amplitude);
  if (h.t.empty() || h.t.back() < b.t_end - 1.01 * b.dt) {
    fmt::print("  warning: the march at {} elements stopped early\n", elements);
    error = std::nan("");
    status = 1;
  }
  o.history_samples = 101;  // the energy on 101 rows (it costs an interior evaluation each)
  o.energy = true;
  const bar::History he = tdbem.simulate(b.setup, o);
  const double energy_change =
      he.energy.empty() ? std::nan("") : (he.energy.back() - he.energy.front()) / he.energy.front();
  const double us = 1e6 * bench::median(seconds) / static_cast<double>(b.steps);
  return {elements, us, error, energy_change};
}

core::Table siconos_table(const core::Table& siconos, const std::vector<SiconosRow>& rows,
                          long steps) {
  core::Table table(
      {"tool", "elements", "steps", "us_per_step", "max_tip_error", "energy_change", "live"});
  for (std::size_t i = 0; i < siconos.rows(); ++i)
    table.add_cells({std::string("siconos"), siconos.column("elements")[i],
                     siconos.column("steps")[i], siconos.column("us_per_step")[i],
                     siconos.column("max_tip_error")[i], siconos.column("energy_change")[i], 0.0});
  for (const SiconosRow& r : rows)
    table.add_cells({std::string("backbone_tdbem"), double(r.elements), double(steps), r.us,
                     r.error, r.energy, 1.0});
  return table;
}

std::string siconos_verdict(const core::Table& siconos, const std::vector<SiconosRow>& rows) {
  const SiconosRow& mid = rows[1];
  return fmt::format(
      "at 100 elements TD-BEM takes {:.3g} us per step, {:.0f}x less than Siconos' {:.3g} us, "
      "with a tip error of {:.2g} against Siconos' {:.2g}, and its energy changes by {:.2g} "
      "against {:.2g}.",
      mid.us, siconos.column("us_per_step")[1] / mid.us, siconos.column("us_per_step")[1],
      mid.error, siconos.column("max_tip_error")[1], mid.energy,
      siconos.column("energy_change")[1]);
}

std::string siconos_section(const core::Table& siconos, const std::vector<SiconosRow>& rows,
                            const std::string& verdict) {
  std::string lines;
  for (std::size_t i = 0; i < siconos.rows(); ++i)
    lines += fmt::format("| Siconos (stored) | {} | {:.3g} | {:.2g} | {:.2g} |\n",
                         siconos.column("elements")[i], siconos.column("us_per_step")[i],
                         siconos.column("max_tip_error")[i], siconos.column("energy_change")[i]);
  for (const SiconosRow& r : rows)
    lines += fmt::format("| backbone TD-BEM | {} | {:.3g} | {:.2g} | {:.2g} |\n", r.elements, r.us,
                         r.error, r.energy);
  return fmt::format(
      "## The Siconos bar: backbone's TD-BEM vs Siconos (`siconos_bar`)\n\n"
      "L = E = rho = A = 1, clamped at x = 0, gap 1e-3 at x = L, u0 = -0.002 x, v0 = "
      "0 (the exact mode 1, T = 3.5, contact on [1.5, 2] at force 0.002), 10 time "
      "units at dt = 1e-3 (10^4 steps). backbone: the TD-BEM march with event "
      "contact, timed without the energy column ({}, median of {}), tip error against "
      "the exact characteristics solution at every step, energy change (E(10) - "
      "E(0)) / E(0) from a second run with the energy on 101 rows. Siconos 4.4: "
      "Moreau-Jean, P1 FEM with consistent mass, theta = 0.5, e = 0, its stored runs "
      "(problems/contact_bar/bench/peers/; not run here).\n\n"
      "| tool | elements | us/step | max tip error / 2e-3 | energy change |\n"
      "|---|---|---|---|---|\n{}\n"
      "**Where backbone stands:** {}\n\n![Siconos bar](siconos_bar.png)\n",
      clock_name(), repetitions, lines, verdict);
}

}  // namespace

int bench_lu_legrand(const std::filesystem::path& out) {
  fmt::print(
      "bench lu_legrand: mode 1, T 3.8 -> 3.01, backbone (TD-BEM shooting) at several grids vs "
      "Lu & Legrand's stored FD-BEM + HBM runs, errors vs the closed form\n");
  const std::vector<LuLegrandRun> stored = read_lu_legrand_runs();
  int status = 0;
  const std::vector<Mode1Trace> traces = trace_lu_legrand_grids(status);
  const Mode1Trace& n20 = traces[1];
  const LuLegrandRun& h20 = stored.front();
  const std::string verdict = fmt::format(
      "at N = 20 backbone costs {:.3g} ms per point ({:.2g}x Lu & Legrand's {:.3g} ms with 20 "
      "harmonics) at a median frequency error of {:.2g} against their {:.2g}; with {} points "
      "where their natural continuation takes {}, the whole range costs {:.3g} s against their "
      "{:.3g} s.",
      1e3 * n20.seconds / n20.points, 1e3 * n20.seconds / n20.points / h20.ms, h20.ms,
      n20.median_error, h20.median, n20.points, h20.points, n20.seconds, h20.seconds);
  bench::PeerFigure figure;
  figure.xlabel = "CPU ms per point (backbone: one thread unless --threads)";
  figure.ylabel = "median relative frequency error (closed form at the point energy)";
  figure.title = "Mode 1, T 3.8 -> 3.01: backbone vs Lu & Legrand (stored)";
  figure.x_column = 5, figure.y_column = 6;
  figure.peer_tool = "lu_legrand";
  figure.peer_title = "Lu & Legrand FD-BEM + HBM (20, 40 harmonics)";
  figure.backbone_tool = "backbone";
  figure.backbone_title = "backbone TD-BEM shooting (N = 10, 20, 40)";
  bench::report_peer_case(out, "lu_legrand", lu_legrand_table(stored, traces), figure, verdict,
                          lu_legrand_section(stored, traces, verdict));
  return status;
}

int bench_siconos_bar(const std::filesystem::path& out) {
  fmt::print(
      "bench siconos_bar: the Siconos bar (mode 1, eps = -0.002, T = 3.5) over 10 time units at "
      "dt = 1e-3, TD-BEM vs Siconos' stored Moreau-Jean runs, tip error vs the exact solution\n");
  const SiconosBar b;
  const exact_bar::ExactBarSolution exact = exact_bar::solve(b.setup, b.t_end);
  const core::Table siconos = core::Table::read_csv(contact_bar_peers_folder() / "siconos_bar.csv");
  int status = 0;
  std::vector<SiconosRow> rows;
  for (int elements : {50, 100, 200}) rows.push_back(march_siconos_bar(b, exact, elements, status));
  const std::string verdict = siconos_verdict(siconos, rows);
  bench::PeerFigure figure;
  figure.xlabel = "CPU microseconds per time step (one thread)";
  figure.ylabel = "max tip error / amplitude 2e-3 (10 time units)";
  figure.title = "Siconos bar, dt = 1e-3, 50/100/200 elements: backbone TD-BEM vs Siconos (stored)";
  figure.x_column = 4, figure.y_column = 5;
  figure.peer_tool = "siconos";
  figure.peer_title = "Siconos Moreau-Jean, P1 FEM, e = 0";
  figure.backbone_tool = "backbone_tdbem";
  figure.backbone_title = "backbone TD-BEM, event contact (errors of 0 at 1e-17)";
  bench::report_peer_case(out, "siconos_bar", siconos_table(siconos, rows, b.steps), figure,
                          verdict, siconos_section(siconos, rows, verdict));
  return status;
}

std::vector<cli::ProblemJob> peer_bench_cases() {
  return {
      {"lu_legrand",
       "mode 1 at N = 10, 20, 40 vs Lu & Legrand's stored FD-BEM + HBM runs (ms/point, error)",
       bench_lu_legrand},
      {"siconos_bar",
       "TD-BEM on the Siconos bar vs Siconos' stored Moreau-Jean runs (us/step, tip error)",
       bench_siconos_bar},
  };
}

}  // namespace backbone::contact_bar
