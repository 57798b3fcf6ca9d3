// Benchmark mode1_scaling (bench.hpp, bench_branch_scaling.hpp): the cost of a whole mode-1
// branch against its closed-form error over N, steps per period, formulation, corrector and
// threads, and the finite-difference Jacobian alone with 1 and 2 threads.
#include "problems/contact_bar/bench/branch_scaling.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "continuation/cli/bench_report.hpp"
#include "core/errors.hpp"
#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "problems/contact_bar/bench/cases.hpp"
#include "problems/contact_bar/bench/metrics.hpp"
#include "problems/contact_bar/bench/peers.hpp"
#include "problems/contact_bar/bench/support.hpp"
#include "problems/contact_bar/cli/trace.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace backbone::contact_bar {

namespace {

double wall_seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The plugin, its keys and the scene of one run, read as `backbone trace` reads them.
struct Mode1Scene {
  cli::ProblemPlugin contact_bar;
  const cli::ProblemPlugin* plugin = nullptr;
  core::Scene scene;
};

void read_mode1_scene(Mode1Scene& s, const Mode1BranchSettings& settings) {
  s.contact_bar = trace_plugin();
  s.plugin = &s.contact_bar;
  s.scene = bench::read_paper_scene(*s.plugin, {"--start_offset",
                                                fmt::format("{:.17g}", settings.start_offset),
                                                "--energy_max",
                                                fmt::format("{:.17g}", settings.energy_max),
                                                "--shooting_elements",
                                                std::to_string(settings.elements),
                                                "--steps_per_period",
                                                std::to_string(settings.steps_per_period),
                                                "--formulation",
                                                settings.formulation,
                                                "--newton",
                                                settings.newton,
                                                "--test_elements",
                                                std::to_string(settings.test_elements),
                                                "--threads",
                                                std::to_string(settings.threads),
                                                "--rank_check_every",
                                                std::to_string(settings.rank_check_every),
                                                "--jacobian",
                                                settings.jacobian,
                                                "--stability",
                                                settings.stability ? "true" : "false"});
}

// The 1-minute load average of the machine (Linux /proc/loadavg), "unknown" elsewhere: wall
// times with threads mean little when other work keeps every core busy.
std::string load_average() {
  std::ifstream file("/proc/loadavg");
  std::string first;
  return file >> first ? first : std::string("unknown");
}

std::string significant(double value) {
  return std::isfinite(value) ? fmt::format("{:.3g}", value) : std::string("-");
}

std::string error_text(double value) {
  return std::isfinite(value) ? fmt::format("{:.1e}", value) : std::string("-");
}

}  // namespace

std::string Mode1BranchSettings::label() const {
  if (study == "grid") return fmt::format("N = {}", elements);
  if (study == "grid_unchecked") return fmt::format("N = {}, no rank checks", elements);
  if (study == "grid_stability") return fmt::format("N = {}, with multipliers", elements);
  if (study.starts_with("grid_exact"))
    return fmt::format(
        "N = {}, {} Jacobian{}", elements, jacobian,
        start_offset == 0.25 ? std::string() : fmt::format(", from {} g0", 1 + start_offset));
  std::string text = fmt::format("N = {}", elements);
  if (steps_per_period != 40) text += fmt::format(", steps_per_period = {}", steps_per_period);
  if (formulation != "regular") text += fmt::format(", {} formulation", formulation);
  if (newton != "eigen" || test_elements != -1)
    text += fmt::format(", newton {}{}", newton,
                        test_elements == 0  ? " (square: test_elements 0)"
                        : test_elements > 0 ? fmt::format(" (test_elements {})", test_elements)
                                            : std::string());
  if (threads != 1) text += fmt::format(", {} threads", threads);
  if (rank_check_every != 1)
    text += rank_check_every == 0 ? std::string(", no rank checks")
                                  : fmt::format(", rank checks every {} points", rank_check_every);
  return text;
}

double Mode1BranchCost::ms_per_point() const {
  return points > 0 ? 1e3 * cpu_seconds / points : std::nan("");
}

double Mode1BranchCost::jacobians_per_point() const {
  return points > 0 ? static_cast<double>(jacobians) / points : std::nan("");
}

Mode1BranchCost trace_mode1_cost(const Mode1BranchSettings& settings) {
  Mode1Scene s;
  read_mode1_scene(s, settings);
  const bench::InProcessTrace t = bench::trace_in_process(*s.plugin, s.scene, "mode1");
  Mode1BranchCost c;
  c.cpu_seconds = t.cpu_seconds;
  c.wall_seconds = t.wall_seconds;
  c.settings = settings;
  const continuation::Branch& branch = t.traced.branch;
  c.points = static_cast<int>(branch.points.size());
  c.message = branch.message;
  c.stop_reason = continuation::to_string(branch.reason);
  c.complete = branch.reason == continuation::StopReason::bound_reached;
  const std::vector<double> errors = bench::mode1_frequency_errors(s.scene, branch);
  for (const continuation::BranchPoint& p : branch.points) {
    c.jacobians += p.jacobian_evaluations;
    c.unknowns.push_back(p.x);
  }
  for (double z : continuation::branch_table(branch).column("sigma_zero"))
    if (std::isfinite(z)) c.sigma_zero = std::max(c.sigma_zero, z);
  c.median_error = bench::median(errors);
  c.worst_error = errors.empty() ? std::nan("") : *std::max_element(errors.begin(), errors.end());
  c.energy_reached =
      branch.points.empty() ? std::nan("") : branch.points.back().observable("energy");
  return c;
}

bool same_branch(const Mode1BranchCost& a, const Mode1BranchCost& b) {
  if (a.unknowns.size() != b.unknowns.size()) return false;
  for (std::size_t i = 0; i < a.unknowns.size(); ++i)
    if (a.unknowns[i].size() != b.unknowns[i].size() ||
        !(a.unknowns[i].array() == b.unknowns[i].array()).all())
      return false;
  return true;
}

core::Table branch_cost_table(const std::vector<Mode1BranchCost>& runs) {
  core::Table table({"study",
                     "setting",
                     "start_offset",
                     "N",
                     "steps_per_period",
                     "formulation",
                     "newton",
                     "test_elements",
                     "threads",
                     "points",
                     "jacobians_per_point",
                     "ms_per_point",
                     "total_seconds",
                     "wall_seconds",
                     "worst_closed_form_error",
                     "median_closed_form_error",
                     "energy_reached",
                     "complete",
                     "jacobian",
                     "sigma_zero_max"});
  for (const Mode1BranchCost& c : runs)
    table.add_cells({c.settings.study,
                     c.settings.label(),
                     c.settings.start_offset,
                     double(c.settings.elements),
                     double(c.settings.steps_per_period),
                     c.settings.formulation,
                     c.settings.newton,
                     double(c.settings.test_elements),
                     double(c.settings.threads),
                     double(c.points),
                     c.jacobians_per_point(),
                     c.ms_per_point(),
                     c.cpu_seconds,
                     c.wall_seconds,
                     c.worst_error,
                     c.median_error,
                     c.energy_reached,
                     c.complete ? 1.0 : 0.0,
                     c.settings.jacobian,
                     c.sigma_zero});
  return table;
}

double time_per_point_exponent(const std::vector<Mode1BranchCost>& runs, int min_elements) {
  std::vector<double> n, ms;
  for (const Mode1BranchCost& c : runs)
    if (c.settings.elements >= min_elements && c.points > 0) {
      n.push_back(c.settings.elements);
      ms.push_back(c.ms_per_point());
    }
  if (n.size() < 2)
    throw core::InputError("N", fmt::format("the exponent over N >= {} needs two or more runs "
                                            "there (got {})",
                                            min_elements, n.size()));
  return log_log_slope(n, ms);
}

std::vector<int> parse_element_list(const std::string& text, const std::string& name) {
  return core::parse_increasing_integers(text, name, 2, 100000, "a grid of intervals");
}

JacobianThreadsTiming time_jacobian_threads(int elements, int repetitions) {
  Mode1BranchSettings settings;
  settings.elements = elements;
  Mode1Scene s;
  read_mode1_scene(s, settings);
  const cli::TraceSetup setup = s.plugin->setup(s.scene, "mode1");
  const core::Problem& problem = *setup.problem;
  JacobianThreadsTiming t;
  t.elements = elements;
  core::Matrix J[2];
  // One Jacobian is short enough to be at the mercy of whatever else the machine schedules
  // while it runs. The repetitions alternate 1 and 2 threads, so that a slow spell hits both,
  // and the medians are compared.
  std::vector<double> wall[2], cpu[2];
  for (int r = 0; r < std::max(repetitions, 1); ++r) {
    for (int k = 0; k < 2; ++k) {
      core::FiniteDifferenceOptions fd;
      fd.threads = k + 1;
      const double cpu_start = bench::process_cpu_seconds();
      const auto wall_start = std::chrono::steady_clock::now();
      const core::EvalStatus status =
          core::finite_difference_jacobian(problem, setup.guess, J[k], fd);
      wall[k].push_back(wall_seconds_since(wall_start));
      cpu[k].push_back(bench::process_cpu_seconds() - cpu_start);
      if (status != core::EvalStatus::ok) J[k].resize(0, 0);  // not identical to anything
    }
  }
  const auto median = bench::median;
  t.rows = static_cast<int>(J[0].rows());
  t.columns = static_cast<int>(J[0].cols());
  t.repetitions = std::max(repetitions, 1);
  t.one_thread_seconds = median(wall[0]), t.two_thread_seconds = median(wall[1]);
  t.one_thread_cpu = median(cpu[0]), t.two_thread_cpu = median(cpu[1]);
  t.identical = J[0].size() > 0 && J[0].rows() == J[1].rows() && J[0].cols() == J[1].cols() &&
                (J[0].array() == J[1].array()).all();
  return t;
}

namespace {

// The grids of the grid studies: BACKBONE_MODE1_SCALING_N, or 20 to 640 by doubling.
std::vector<int> scaling_grids() {
  const char* grids_env = std::getenv("BACKBONE_MODE1_SCALING_N");
  return parse_element_list(grids_env && *grids_env ? grids_env : "20,40,80,160,320,640");
}

// The variants sit at N = 40, threads at 80 (where a residual costs enough to share), each
// beside its baseline, the grid row of the same N; the Jacobian alone is timed at N = 200.
constexpr int variant_n = 40, threads_n = 80, jacobian_n = 200;

// Every run of the case: `all` in the table's order, the rest by study.
struct ScalingRuns {
  std::vector<Mode1BranchCost> all, grid, fine, unchecked, exact, stability;
  Mode1BranchCost base, spp80, paper, eigen_square, kinsol_square, threads_base, threads;
  bool threads_same = false;
  int status = 0;  // 1 when a grid run stops early or threads change the branch

  // Traces one setting, appends it to `all` and prints its line. A run under 2 s of CPU is
  // repeated and timed at its best (the branch is the same each time): the machine's load
  // inflates even CPU time, most on short runs.
  const Mode1BranchCost& run(const Mode1BranchSettings& settings) {
    const double short_run_seconds = 2;
    all.push_back(trace_mode1_cost(settings));
    Mode1BranchCost& c = all.back();
    for (int k = 1; k < 3 && c.cpu_seconds < short_run_seconds; ++k) {
      const Mode1BranchCost again = trace_mode1_cost(settings);
      if (again.cpu_seconds < c.cpu_seconds)
        c.cpu_seconds = again.cpu_seconds, c.wall_seconds = again.wall_seconds;
    }
    fmt::print("  {:<50} {:>5} points {:>7.3g} ms/point (CPU) {:>8.3g} s  worst error {:.2e}{}\n",
               settings.label(), c.points, c.ms_per_point(), c.cpu_seconds, c.worst_error,
               c.complete ? "" : "  stopped early: " + c.message);
    std::fflush(stdout);  // a long bench shows its progress run by run
    return c;
  }
  // Runs a grid study's setting into `study`; an incomplete branch sets status 1.
  void run_into(std::vector<Mode1BranchCost>& study, const Mode1BranchSettings& settings) {
    study.push_back(run(settings));
    if (!study.back().complete) status = 1;
  }
  // The grid row of N, or a baseline run when the grids skip N.
  Mode1BranchCost grid_run(int n) {
    for (const Mode1BranchCost& c : grid)
      if (c.settings.elements == n) return c;
    Mode1BranchSettings s;
    s.study = "baseline";
    s.elements = n;
    return run(s);
  }
};

// The grid studies: the grids at 40 steps per period, at 2 N, and without rank reports.
void run_grid_studies(ScalingRuns& r, const std::vector<int>& grids) {
  for (int n : grids) {
    Mode1BranchSettings s;
    s.elements = n;
    r.run_into(r.grid, s);
  }
  // The same grids at steps_per_period = 2 N (Courant number c dt / dx = T / 2L, about 1.75):
  // a row of the shooting residual then depends on u0 over a few elements about each
  // characteristic image, so the compressed Jacobian needs a number of colours independent of
  // N, where the trace's 40 steps need about N / 2 (problems/contact_bar/bench/README.md, 'Cost').
  for (int n : grids) {
    if (2 * n <= 40) continue;  // that grid row is this setting already
    Mode1BranchSettings s;
    s.study = "grid_2N";
    s.elements = n;
    s.steps_per_period = 2 * n;
    r.run_into(r.fine, s);
  }
  // The exact Jacobian (orbits/README.md, 'Exact Jacobian', the trace's default) against the
  // differences on the same grids, in one loop so that each pair runs back to back: from the
  // grid rows' start (1.25 g0, T = 3.8: a branch point, whose null space the attached family
  // shares)
  // and from the trace's default start (1.05 g0, T = 83/21: a family with p = 42, which none of
  // these grids holds).
  for (int n : grids)
    for (const double start_offset : {0.25, 0.05})
      for (const auto& [study, jacobian] :
           {std::pair{"grid_exact", "exact"}, std::pair{"grid_exact_differences", "differences"}}) {
        Mode1BranchSettings s;
        s.study = study;
        s.elements = n;
        s.jacobian = jacobian;
        s.start_offset = start_offset;
        r.run_into(r.exact, s);
      }
  // The same grids with the multipliers of every point (--stability true, the fronts' K:
  // orbits/README.md, 'Stability'), against the grid rows above.
  for (int n : grids) {
    Mode1BranchSettings s;
    s.study = "grid_stability";
    s.elements = n;
    s.stability = true;
    r.run_into(r.stability, s);
  }
  // Without rank reports (--rank_check_every 0), up to N = 640: what the corrections cost
  // alone, without the verification of the many-dimensional start at T = 3.8, which dominates
  // the checked trace at large N (problems/contact_bar/bench/README.md, 'Cost').
  for (int n : {40, 80, 160, 320, 640}) {
    Mode1BranchSettings s;
    s.study = "grid_unchecked";
    s.elements = n;
    s.rank_check_every = 0;
    r.run_into(r.unchecked, s);
  }
}

// The variants: steps per period, formulation, corrector and threads, each at its N.
void run_variants(ScalingRuns& r) {
  r.base = r.grid_run(variant_n);
  r.threads_base = r.grid_run(threads_n);
  Mode1BranchSettings spp;
  spp.study = "steps_per_period";
  spp.elements = variant_n;
  spp.steps_per_period = 80;
  r.spp80 = r.run(spp);
  Mode1BranchSettings paper;
  paper.study = "formulation";
  paper.elements = variant_n;
  paper.formulation = "paper";
  r.paper = r.run(paper);
  Mode1BranchSettings square;
  square.study = "corrector";
  square.elements = variant_n;
  square.test_elements = 0;
  r.eigen_square = r.run(square);
  square.newton = "kinsol";
  r.kinsol_square = r.run(square);
  Mode1BranchSettings two;
  two.study = "threads";
  two.elements = threads_n;
  two.threads = 2;
  r.threads = r.run(two);
  r.threads_same = same_branch(r.threads_base, r.threads);
  fmt::print("  2 threads at N = {}: {} branch as 1 thread\n", threads_n,
             r.threads_same ? "the same" : "NOT the same");
  if (!r.threads_same) r.status = 1;
}

// The exponent of ms per point over N >= 40 (NaN without two such grids), the constant of its
// fit line and the point count of the largest grid against N = 40.
struct GridFit {
  double exponent = std::nan("");
  double constant = std::nan("");  // C of ms = C N^p through the geometric mean of the runs
  double point_ratio = 0;
  const Mode1BranchCost* largest = nullptr;
  const Mode1BranchCost* n160 = nullptr;  // the grid row of N = 160, if run
};

GridFit fit_grid(const ScalingRuns& r, const std::vector<int>& grids) {
  GridFit f;
  if (grids.size() >= 2 &&
      std::count_if(grids.begin(), grids.end(), [](int n) { return n >= 40; }) >= 2)
    f.exponent = time_per_point_exponent(r.grid, 40);
  f.largest = &r.grid.back();
  f.point_ratio = static_cast<double>(f.largest->points) / r.base.points;
  for (const Mode1BranchCost& c : r.grid)
    if (c.settings.elements == 160) f.n160 = &c;
  fmt::print(
      "  exponent of ms per point over N >= 40: {:.3f}; points at N = {} / at N = 40: {:.3g}\n",
      f.exponent, f.largest->settings.elements, f.point_ratio);
  if (std::isfinite(f.exponent)) {
    double log_c = 0;
    int count = 0;
    for (const Mode1BranchCost& c : r.grid)
      if (c.settings.elements >= 40)
        log_c += std::log(c.ms_per_point()) - f.exponent * std::log(c.settings.elements), ++count;
    f.constant = std::exp(log_c / count);
  }
  return f;
}

// Left: ms per point vs N with the fit; right: worst error vs CPU seconds per branch.
void plot_scaling(const std::filesystem::path& csv, const std::filesystem::path& png,
                  const GridFit& fit) {
  const std::string q = core::gnuplot_quote(csv);
  const std::string fit_clause =
      std::isfinite(fit.exponent)
          ? fmt::format(", ({:.6g})*x**({:.6g}) dt 2 lw 2 title 'fit N^{:.2f} (N >= 40)'",
                        fit.constant, fit.exponent, fit.exponent)
          : std::string();
  bench::plot(
      png,
      fmt::format(
          "set termoption noenhanced\nset multiplot layout 1,2\nset logscale xy\nset grid\n"
          "floor = {2}\n"
          "err(d) = column('worst_closed_form_error') > floor ? "
          "column('worst_closed_form_error') : floor\n"
          "cpu(s) = strcol('study') eq s && column('complete') == 1 ? "
          "column('total_seconds') : NaN\n"
          "square(n) = strcol('study') eq 'corrector' && strcol('newton') eq n && "
          "column('complete') == 1 ? column('total_seconds') : NaN\n"
          "set key left top\nset xlabel 'shooting intervals N'\n"
          "set ylabel 'CPU ms per point'\nset title 'Mode 1, T 3.8 -> 3.01: cost per point'\n"
          "plot {0} using (strcol('study') eq 'grid' ? column('N') : NaN):'ms_per_point' "
          "with linespoints pt 7 ps 1.5 title 'regular, eigen, 1 thread, 40 steps per "
          "period'{1}, {0} using (strcol('study') eq 'grid_unchecked' ? column('N') : NaN):"
          "'ms_per_point' with linespoints pt 6 ps 1.5 title 'the same without rank checks', "
          "25 dt 3 title 'target at N = 160: 25 ms'\n"
          "set format y '%.0e'\nset xlabel 'CPU seconds per branch'\n"
          "set ylabel 'worst relative frequency error (closed form)'\n"
          "set title 'Work-precision: whole branches that reach E = 5e-3 (errors of 0 at "
          "1e-17)'\nset key left top\n"
          "plot {0} using (cpu('grid')):(err(0)) with linespoints pt 7 ps 1.5 title 'N "
          "(labels): regular, eigen, 1 thread', "
          "{0} using (cpu('grid')):(err(0)):(sprintf('%d', column('N'))) with labels offset "
          "0,1 notitle, "
          "{0} using (cpu('steps_per_period')):(err(0)) with points pt 5 ps 1.5 title 'N = "
          "40, 80 steps per period', "
          "{0} using (cpu('formulation')):(err(0)) with points pt 9 ps 1.5 title 'N = 40, "
          "paper formulation (drawn only if it reaches the bound)', "
          "{0} using (square('eigen')):(err(0)) with points pt 11 ps 1.5 title 'N = 40, "
          "square system, eigen', "
          "{0} using (square('kinsol')):(err(0)) with points pt 13 ps 1.5 title 'N = 40, "
          "square system, kinsol', "
          "{0} using (cpu('threads')):(err(0)) with points pt 3 ps 2 lw 2 title 'N = 80, 2 "
          "threads (CPU of both)'\n"
          "unset multiplot\n",
          q, fit_clause, bench::plot_floor),
      {1600, 700});
}

// One row of the BENCHMARKS.md tables.
std::string cost_row(const Mode1BranchCost& c) {
  const std::string stopped =
      c.complete ? std::string()
                 : fmt::format(" (stopped at E = {:.2g}: {})", c.energy_reached, c.stop_reason);
  return fmt::format("| {}{} | {} | {} | {} | {} | {} | {} | {} |\n", c.settings.label(), stopped,
                     c.points, significant(c.jacobians_per_point()), significant(c.ms_per_point()),
                     significant(c.cpu_seconds), error_text(c.worst_error),
                     error_text(c.median_error), error_text(c.sigma_zero));
}

// The multipliers' cost, grid by grid: ms per point with and without them, and the exponent
// of their extra cost over N >= 40.
std::string stability_verdict(const ScalingRuns& r) {
  std::string rows;
  std::vector<double> n, extra;
  for (const Mode1BranchCost& s : r.stability)
    for (const Mode1BranchCost& g : r.grid)
      if (g.settings.elements == s.settings.elements) {
        rows += fmt::format("{}N = {}: {} against {} ({:.2f}x)", rows.empty() ? "" : "; ",
                            s.settings.elements, significant(s.ms_per_point()),
                            significant(g.ms_per_point()), s.ms_per_point() / g.ms_per_point());
        if (s.settings.elements >= 40 && s.ms_per_point() > g.ms_per_point()) {
          n.push_back(s.settings.elements);
          extra.push_back(s.ms_per_point() - g.ms_per_point());
        }
      }
  if (rows.empty()) return std::string();
  const std::string growth =
      n.size() >= 2 ? fmt::format(
                          " The multipliers' extra ms per point grow like N^{:.2f} over "
                          "N >= 40.",
                          log_log_slope(n, extra))
                    : std::string();
  return " With the multipliers of every point (`--stability true`), ms per point against "
         "without: " +
         rows + "." + growth;
}

// The exact Jacobian against the differences, grid by grid: ms per point and sigma_zero.
std::string exact_verdict(const ScalingRuns& r) {
  std::string rows;
  for (const Mode1BranchCost& e : r.exact)
    for (const Mode1BranchCost& d : r.exact)
      if (e.settings.jacobian == "exact" && d.settings.jacobian == "differences" &&
          d.settings.elements == e.settings.elements &&
          d.settings.start_offset == e.settings.start_offset)
        rows +=
            fmt::format("{}N = {}{}: {} against {} ms per point, sigma_zero at most {} against {}",
                        rows.empty() ? "" : "; ", e.settings.elements,
                        e.settings.start_offset == 0.25
                            ? std::string()
                            : fmt::format(" from {} g0", 1 + e.settings.start_offset),
                        significant(e.ms_per_point()), significant(d.ms_per_point()),
                        error_text(e.sigma_zero), error_text(d.sigma_zero));
  return rows.empty() ? std::string()
                      : " With the exact Jacobian (`--jacobian exact`): " + rows + ".";
}

std::string grid_verdict(const ScalingRuns& r, const GridFit& f) {
  const Mode1BranchCost& largest = *f.largest;
  return fmt::format(
      "ms per point grows like N^{:.2f} over N >= 40 (target <= 1.5: {}), N = 160 costs {} ms "
      "per point (target <= 25: {}), and N = {} takes {:.3g}x the points of N = 40 (target "
      "within 2x at 640: {}); Jacobians per point grow from {:.3g} at N = 40 to {:.3g} at N = "
      "{}.",
      f.exponent, f.exponent <= 1.5 ? "met" : "not met",
      f.n160 ? significant(f.n160->ms_per_point()) : std::string("(not run)"),
      f.n160 ? (f.n160->ms_per_point() <= 25 ? "met" : "not met") : "not measured",
      largest.settings.elements, f.point_ratio,
      largest.settings.elements < 640 ? "640 not run here"
                                      : (f.point_ratio <= 2 ? "met" : "not met"),
      r.base.jacobians_per_point(), largest.jacobians_per_point(), largest.settings.elements);
}

std::string unchecked_verdict(const ScalingRuns& r) {
  const double unchecked_points =
      static_cast<double>(r.unchecked.back().points) / r.unchecked.front().points;
  const double unchecked_exponent = time_per_point_exponent(r.unchecked, 40);
  return fmt::format(
      " Without rank checks (`--rank_check_every 0`), ms per point grows like N^{:.2f} over N = "
      "40..640 ({} ms per point at 640, worst error {}) and N = 640 takes {:.3g}x the points of "
      "N = 40.",
      unchecked_exponent, significant(r.unchecked.back().ms_per_point()),
      error_text(r.unchecked.back().worst_error), unchecked_points);
}

// Empty without two grid_2N runs at N >= 40.
std::string fine_verdict(const ScalingRuns& r) {
  if (std::count_if(r.fine.begin(), r.fine.end(),
                    [](const Mode1BranchCost& c) { return c.settings.elements >= 40; }) < 2)
    return std::string();
  const Mode1BranchCost* fine160 = nullptr;
  for (const Mode1BranchCost& c : r.fine)
    if (c.settings.elements == 160) fine160 = &c;
  return fmt::format(
      " At steps_per_period = 2 N, ms per point grows like N^{:.2f} over N >= 40{}, with {:.3g} "
      "Jacobians per point at N = {}.",
      time_per_point_exponent(r.fine, 40),
      fine160
          ? fmt::format(" and N = 160 costs {} ms per point", significant(fine160->ms_per_point()))
          : std::string(),
      r.fine.back().jacobians_per_point(), r.fine.back().settings.elements);
}

std::string variant_verdict(const ScalingRuns& r) {
  const Mode1BranchCost& base = r.base;
  return fmt::format(
      "at N = 40, 80 steps per period cost {:.2g}x the CPU of 40 for a worst error of {} against "
      "{}; the paper formulation {}; the square system costs {:.2g}x (eigen) and {:.2g}x "
      "(kinsol) the overdetermined one; 2 threads at N = {} give {} branch at {:.2g}x the wall "
      "time and {:.2g}x the CPU time of one thread.",
      r.spp80.cpu_seconds / base.cpu_seconds, error_text(r.spp80.worst_error),
      error_text(base.worst_error),
      r.paper.complete
          ? fmt::format("reaches the bound at {:.2g}x the CPU with a worst error of {}",
                        r.paper.cpu_seconds / base.cpu_seconds, error_text(r.paper.worst_error))
          : fmt::format(
                "stops at E = {:.3g} after {} point(s) ({}: its Jacobian is degenerate "
                "on the family, problems/contact_bar/orbits/README.md, section 'Shooting on the "
                "bar'), so it has no branch cost to compare",
                r.paper.energy_reached, r.paper.points, r.paper.stop_reason),
      r.eigen_square.cpu_seconds / base.cpu_seconds, r.kinsol_square.cpu_seconds / base.cpu_seconds,
      threads_n, r.threads_same ? "the same (bit for bit)" : "a DIFFERENT",
      r.threads.wall_seconds / r.threads_base.wall_seconds,
      r.threads.cpu_seconds / r.threads_base.cpu_seconds);
}

std::string jacobian_verdict(const JacobianThreadsTiming& jt, const std::string& load) {
  return fmt::format(
      "2 threads compute the {} x {} Jacobian {:.3g}x faster than one (target >= 1.7x: {}), "
      "{}; these are wall times on a machine of {} cores with a load average of {} when they "
      "were taken: the 2 threads ran on {:.2g} cores on average (process CPU / wall), and "
      "their CPU time is {:.2g}x that of one thread (the cost of sharing the work).",
      jt.rows, jt.columns, jt.speedup(), jt.speedup() >= 1.7 ? "met" : "not met",
      jt.identical ? "bit-identical to one thread's" : "NOT identical to one thread's",
      std::thread::hardware_concurrency(), load, jt.two_thread_cpu / jt.two_thread_seconds,
      jt.two_thread_cpu / jt.one_thread_cpu);
}

// BENCHMARKS.md: the grid table, the variants, the Jacobian alone.
std::string scaling_section(const ScalingRuns& r, const JacobianThreadsTiming& jt,
                            const std::string& grid_verdicts, const std::string& variants,
                            const std::string& jacobian) {
  const std::string header =
      "| setting | points | Jacobians/point | ms/point (CPU) | total CPU s | worst error | "
      "median error | sigma_zero max |\n|---|---|---|---|---|---|---|---|\n";
  std::string grid_rows, variant_rows;
  for (const std::vector<Mode1BranchCost>* study :
       {&r.grid, &r.fine, &r.unchecked, &r.exact, &r.stability})
    for (const Mode1BranchCost& c : *study) grid_rows += cost_row(c);
  for (const Mode1BranchCost* c : {&r.base, &r.spp80, &r.paper, &r.eigen_square, &r.kinsol_square,
                                   &r.threads_base, &r.threads})
    variant_rows += cost_row(*c);
  return fmt::format(
      "## Mode 1 of the contact bar: branch cost against error (`mode1_scaling`)\n\n"
      "Mode 1 of the paper scene from T = 3.8 to 3.01: `trace "
      "problems/contact_bar/scenes/paper.ini --branch mode1 --start_offset 0.25 "
      "--energy_max 5e-3 --shooting_elements N`; the rows 'from 1.05 g0' start at the "
      "trace's default, `--start_offset 0.05` (T = 83/21) (ds 0.45, steps_per_period 40, regular "
      "formulation, eigen least squares, one thread unless stated), run in-process, one "
      "run each (best of 3 for runs under 2 s CPU). Time: process CPU seconds of the "
      "continuation (all threads), since the "
      "machine may be shared; Jacobians per point: BranchPoint::jacobian_evaluations "
      "averaged. Error: |omega / omega_exact(E) - 1| against the mode-1 closed form at "
      "each point's own energy. Grids: BACKBONE_MODE1_SCALING_N (default "
      "20,40,80,160,320,640; "
      "`BACKBONE_MODE1_SCALING_N=20,40,80,160,320,640,1000 backbone bench --case "
      "mode1_scaling` adds N = 1000).\n\n"
      "### Over the grid\n\n{0}{1}\n**Where backbone stands:** {2}\n\n"
      "### Steps per period, formulation, corrector, threads\n\n{0}{3}\n"
      "**Where backbone stands:** {4}\n\n"
      "### The finite-difference Jacobian alone, 1 vs 2 threads\n\n"
      "At the trace's first point (the closed-form orbit of end amplitude 1.25 g0), N = {5}, "
      "core::finite_difference_jacobian, {11} runs of each in alternation, median times.\n\n"
      "| threads | wall s | process CPU s |\n|---|---|---|\n| 1 | {6:.4g} | {7:.4g} |\n"
      "| 2 | {8:.4g} | {9:.4g} |\n\n**Where backbone stands:** {10}\n\n"
      "![Mode 1 cost per point and work-precision](mode1_scaling.png)\n",
      header, grid_rows, grid_verdicts, variant_rows, variants, jacobian_n, jt.one_thread_seconds,
      jt.one_thread_cpu, jt.two_thread_seconds, jt.two_thread_cpu, jacobian, jt.repetitions);
}

}  // namespace

int bench_mode1_scaling(const std::filesystem::path& out) {
  const std::vector<int> grids = scaling_grids();
  fmt::print(
      "bench mode1_scaling: mode 1, T 3.8 -> 3.01 (paper scene, start_offset 0.25, and 0.05 "
      "for the exact Jacobian's study; energy_max 5e-3), whole-branch cost vs closed-form error "
      "over N = {} (BACKBONE_MODE1_SCALING_N), "
      "steps per period, formulation, corrector and threads\n",
      fmt::join(grids, ", "));
  ScalingRuns r;
  run_grid_studies(r, grids);
  run_variants(r);

  const std::string load = load_average();
  const JacobianThreadsTiming jt = time_jacobian_threads(jacobian_n);
  fmt::print(
      "  FD Jacobian alone at N = {} ({} x {}), median of {} alternating runs: 1 thread {:.4g} s, "
      "2 threads "
      "{:.4g} s, speedup {:.3g}x, {}\n",
      jacobian_n, jt.rows, jt.columns, jt.repetitions, jt.one_thread_seconds, jt.two_thread_seconds,
      jt.speedup(), jt.identical ? "bit-identical" : "NOT identical");
  if (!jt.identical) r.status = 1;

  const std::filesystem::path csv =
      bench::write_table(branch_cost_table(r.all), out, "mode1_scaling", 3);
  const GridFit fit = fit_grid(r, grids);
  plot_scaling(csv, out / "mode1_scaling.png", fit);

  const std::string grid = grid_verdict(r, fit);
  const std::string unchecked = unchecked_verdict(r);
  const std::string exact = exact_verdict(r);
  const std::string stability = stability_verdict(r);
  fmt::print("  {}\n  {}\n  {}\n", unchecked, exact, stability);
  const std::string fine = fine_verdict(r);
  const std::string variants = variant_verdict(r);
  const std::string jacobian = jacobian_verdict(jt, load);
  fmt::print("  {}\n  {}\n  {}\n", grid, variants, jacobian);
  cli::write_bench_section(
      out, "mode1_scaling",
      scaling_section(r, jt, grid + fine + unchecked + exact + stability, variants, jacobian));
  return r.status;
}

}  // namespace backbone::contact_bar
