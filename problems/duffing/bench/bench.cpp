// Benchmark duffing_auto (bench.hpp): backbone against AUTO-07p on the Duffing backbone.
#include "problems/duffing/bench/bench.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <numbers>
#include <sstream>

#include "continuation/cli/bench_report.hpp"
#include "continuation/cli/scene_options.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "core/errors.hpp"
#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "core/solvers/newton.hpp"
#include "problems/duffing/duffing.hpp"

#ifndef BACKBONE_DUFFING_PEERS_DIR
#define BACKBONE_DUFFING_PEERS_DIR "problems/duffing/bench/peers"
#endif

namespace backbone::duffing {

namespace {

constexpr const char* auto_driver = "/usr/lib/auto-07p/python/auto/interactiveBindings.py";

double cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

bool on_path(const std::string& program) {
  return std::system(fmt::format("command -v {} > /dev/null 2>&1", program).c_str()) == 0;
}

std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Amplitude of the Duffing orbit of energy H: the root of A^2/2 + A^4/4 = H.
double amplitude_of_energy(double energy) {
  return std::sqrt(std::sqrt(1.0 + 4.0 * energy) - 1.0);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// What a traced branch says, timed from (wall_start, cpu_start): seconds, points, stop, counts,
// and the worst relative period error against the elliptic integral.
BackboneRun measured_run(const continuation::Branch& branch, const Duffing& duffing,
                         std::chrono::steady_clock::time_point wall_start, double cpu_start) {
  BackboneRun run;
  run.cpu_seconds = cpu_now() - cpu_start;
  run.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  run.points = static_cast<int>(branch.points.size());
  run.message = branch.message;
  run.residuals = duffing.counters().residuals;
  run.jacobians = duffing.counters().jacobians;
  for (const continuation::BranchPoint& p : branch.points) {
    const double exact = exact_period(p.x[0]);
    run.max_error = std::max(run.max_error, std::abs(p.x[1] - exact) / exact);
  }
  return run;
}

}  // namespace

std::filesystem::path peers_folder() {
  const std::filesystem::path built_in = BACKBONE_DUFFING_PEERS_DIR;
  if (std::filesystem::exists(built_in / "duffing.f90")) return built_in;
  return "problems/duffing/bench/peers";  // a moved source tree: relative to the repository root
}

BackboneRun trace_backbone(const BackboneSettings& settings) {
  DuffingOptions duffing_options;
  duffing_options.relative_tolerance = settings.relative_tolerance;
  const Duffing duffing(duffing_options);
  if (!(settings.amplitude_start > 0 && settings.amplitude_end > settings.amplitude_start))
    throw core::InputError("amplitude_end",
                           fmt::format("must be > amplitude_start > 0 (got {}, {})",
                                       settings.amplitude_end, settings.amplitude_start));
  continuation::ContinuationOptions options;
  options.ds = settings.ds;
  options.ds_max = settings.ds_max;
  options.max_points = 100000;
  options.rank_check_every = settings.rank_check_every;
  options.verify = settings.rank_check_every > 0;
  options.bounds.push_back({"amplitude", 0.5 * settings.amplitude_start, settings.amplitude_end});
  core::NewtonOptions newton;
  newton.residual_tolerance = settings.newton_tolerance;
  const auto corrector = core::make_corrector("eigen", newton);
  core::Vector guess(2);
  guess << settings.amplitude_start, 2.0 * std::numbers::pi;
  const core::Vector direction = core::Vector::Unit(2, 0);

  const auto wall_start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_now();
  const continuation::Branch branch =
      continuation::pseudo_arclength(duffing, guess, direction, *corrector, options);
  BackboneRun run = measured_run(branch, duffing, wall_start, cpu_start);
  run.settings = settings;
  run.complete =
      branch.reason == continuation::StopReason::bound_reached && !branch.points.empty() &&
      std::abs(branch.points.back().x[0] - settings.amplitude_end) <= 1e-9 * settings.amplitude_end;
  return run;
}

bool auto07p_available(std::string& why) {
  std::vector<std::string> missing;
  if (!std::filesystem::exists(auto_driver)) missing.push_back("auto-07p");
  for (const char* program : {"gfortran", "make", "python3"})
    if (!on_path(program)) missing.push_back(program);
  if (missing.empty()) return true;
  std::string list;
  for (const std::string& m : missing) list += (list.empty() ? "" : ", ") + m;
  why = fmt::format("not installed: {} (apt-get install -y auto-07p gfortran make)", list);
  return false;
}

AutoRun read_auto07p_branch(const std::filesystem::path& branch_file) {
  std::ifstream in(branch_file);
  if (!in)
    throw core::InputError("b.duffing", fmt::format("cannot read '{}'", branch_file.string()));
  AutoRun run;
  std::string line;
  // Data rows of a periodic-orbit branch: BR PT TY LAB mu L2-NORM MAX-x MAX-v PERIOD H A AH
  // (AUTO writes BR negative for unlabelled points); header rows start with BR = 0.
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (w.size() != 12 || w[0] == "0") continue;
    const double period = std::strtod(w[8].c_str(), nullptr);
    const double energy = std::strtod(w[9].c_str(), nullptr);
    if (!(energy > 0) || !(period > 0)) continue;  // the Hopf point (amplitude 0)
    const double exact = exact_period(amplitude_of_energy(energy));
    run.max_error = std::max(run.max_error, std::abs(period - exact) / exact);
    ++run.points;
  }
  if (run.points == 0)
    throw core::InputError("b.duffing",
                           fmt::format("'{}' holds no periodic orbit", branch_file.string()));
  return run;
}

std::optional<AutoRun> run_auto07p(int ntst, double amax, const std::filesystem::path& folder,
                                   std::string& why) {
  std::filesystem::create_directories(folder);
  for (const char* file : {"duffing.f90", "duffing.auto"})
    std::filesystem::copy_file(peers_folder() / file, folder / file,
                               std::filesystem::copy_options::overwrite_existing);
  std::filesystem::remove(folder / "b.duffing");
  const std::string command = fmt::format(
      "cd {} && OMP_NUM_THREADS=1 NTST={} AMAX={} python3 {} duffing.auto > auto.log 2>&1",
      shell_quote(folder.string()), ntst, amax, auto_driver);
  if (std::system(command.c_str()) != 0 || !std::filesystem::exists(folder / "b.duffing")) {
    why = fmt::format("AUTO-07p failed (see {})", (folder / "auto.log").string());
    return std::nullopt;
  }
  // "Total Time" once per run: the equilibrium run, then the periodic orbits (the backbone).
  const std::string log = read_text(folder / "auto.log");
  const std::string key = "Total Time";
  const std::size_t at = log.rfind(key);
  if (at == std::string::npos) {
    why = "AUTO-07p printed no Total Time";
    return std::nullopt;
  }
  AutoRun run = read_auto07p_branch(folder / "b.duffing");
  run.seconds = std::strtod(log.c_str() + at + key.size(), nullptr);
  run.ntst = ntst;
  run.live = true;
  return run;
}

std::vector<AutoRun> stored_auto07p_runs() {
  const core::Table table = core::Table::read_csv(peers_folder() / "auto07p_runs.csv");
  std::vector<AutoRun> runs;
  const std::vector<double> ntst = table.column("ntst"), points = table.column("points"),
                            seconds = table.column("seconds"), error = table.column("max_error");
  for (std::size_t i = 0; i < table.rows(); ++i)
    runs.push_back(
        {static_cast<int>(ntst[i]), false, static_cast<int>(points[i]), seconds[i], error[i]});
  return runs;
}

namespace {

constexpr int repetitions = 3;          // medians of 3, as the stored peer runs
constexpr int paired_repetitions = 11;  // the CLI defaults against AUTO-07p NTST 50

// The AUTO-07p runs of the case, and where they come from.
}  // namespace

BackboneRun trace_scene_defaults() {
  const std::string scene_path = core::shipped_path("problems/duffing/scenes/duffing.ini").string();
  namespace po = boost::program_options;
  po::options_description keys = scene_keys();
  keys.add(cli::continuation_keys(keys));
  const core::Scene scene =
      core::read_scene(keys, scene_path, {"--bound", "amplitude:0.005:5"}, {});
  const cli::RunSettings run = cli::read_run_settings(scene);
  DuffingOptions duffing_options;
  duffing_options.relative_tolerance = scene.positive("rtol");
  const Duffing duffing(duffing_options);
  const auto corrector = core::make_corrector(run.newton, run.newton_options);
  core::Vector guess(2);
  guess << scene.positive("amplitude"), 2.0 * std::numbers::pi;
  const core::Vector direction = core::Vector::Unit(2, 0);

  const auto wall_start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_now();
  const continuation::Branch branch =
      cli::run_continuation(duffing, guess, direction, run, *corrector, {}).branch;
  BackboneRun result = measured_run(branch, duffing, wall_start, cpu_start);
  result.settings.relative_tolerance = duffing_options.relative_tolerance;
  result.settings.ds = run.options.ds;
  result.settings.ds_max = run.options.ds_max;
  result.settings.newton_tolerance = run.newton_options.residual_tolerance;
  result.settings.rank_check_every = run.options.rank_check_every;
  result.label = "CLI defaults (duffing.ini), rank reports, multipliers";
  result.complete = branch.reason == continuation::StopReason::bound_reached;
  return result;
}

namespace {

struct AutoRuns {
  std::vector<AutoRun> runs;
  bool live = false;   // run in this bench (false: the stored runs)
  std::string source;  // for the section: "run live in this bench" or why the stored runs
};

// AUTO-07p at NTST 20 and 50, live when installed, the stored runs otherwise or when a live run
// fails. AUTO and backbone alternate, so that both see the same load on a shared machine.
AutoRuns auto07p_runs(const BackboneSettings& headline) {
  AutoRuns a;
  std::string why;
  const bool installed = auto07p_available(why);
  a.source = "run live in this bench";
  if (!installed) {
    fmt::print("  AUTO-07p {}: using the stored runs\n", why);
    a.source =
        fmt::format("{}: the stored runs of problems/duffing/bench/peers/auto07p_runs.csv", why);
  }
  const std::filesystem::path scratch =
      std::filesystem::temp_directory_path() / fmt::format("backbone_auto07p_{}", ::getpid());
  a.live = installed;
  if (installed) {
    for (int ntst : {20, 50}) {
      std::vector<double> seconds;
      std::optional<AutoRun> run;
      for (int k = 0; k < repetitions && (k == 0 || run); ++k) {
        run = run_auto07p(ntst, headline.amplitude_end, scratch, why);
        if (run) seconds.push_back(run->seconds);
        trace_backbone(headline);  // same load
      }
      if (!run) {
        fmt::print("  {}: using the stored runs\n", why);
        a.source = fmt::format("{}: the stored runs", why);
        a.runs.clear();
        a.live = false;
        break;
      }
      run->seconds = median(seconds);
      a.runs.push_back(*run);
    }
    std::filesystem::remove_all(scratch);
  }
  if (a.runs.empty()) a.runs = stored_auto07p_runs();
  return a;
}

// backbone's settings: CVODE tolerances 1e-8 to 1e-13 at step caps 0.25 and 1.
std::vector<BackboneSettings> backbone_sweep(const BackboneSettings& headline) {
  std::vector<BackboneSettings> sweep;
  for (double ds_max : {0.25, 1.0})
    for (double rtol : {1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13}) {
      BackboneSettings s = headline;
      s.relative_tolerance = rtol;
      s.ds_max = ds_max;
      s.ds = std::min(s.ds, ds_max);
      // The residual cannot be converged below the integration error (dT/T ~ F / 3).
      s.newton_tolerance = std::max(headline.newton_tolerance, rtol);
      sweep.push_back(s);
    }
  return sweep;
}

// Each setting traced `repetitions` times: seconds are the median wall time beside live AUTO
// runs and the median CPU time beside stored ones (an idle core: a loaded machine inflates wall
// time). status 1 when a trace stops early.
std::vector<BackboneRun> run_sweep(const std::vector<BackboneSettings>& sweep, bool live,
                                   int& status) {
  std::vector<BackboneRun> runs;
  for (const BackboneSettings& s : sweep) {
    std::vector<double> seconds, cpu;
    BackboneRun run;
    for (int k = 0; k < repetitions; ++k) {
      run = trace_backbone(s);
      seconds.push_back(run.seconds);
      cpu.push_back(run.cpu_seconds);
    }
    run.seconds = median(live ? seconds : cpu);
    run.cpu_seconds = median(cpu);
    if (!run.complete) {
      fmt::print("  warning: rtol {:g} ds_max {:g} stopped early: {}\n", s.relative_tolerance,
                 s.ds_max, run.message);
      status = 1;
    }
    runs.push_back(run);
  }
  return runs;
}

core::Table duffing_table(const std::vector<AutoRun>& autos, const std::vector<BackboneRun>& runs) {
  core::Table table({"tool", "setting", "ntst", "rtol", "ds_max", "points", "seconds",
                     "ms_per_point", "max_error", "live", "residuals", "jacobians", "cpu_seconds"});
  const double nan = std::nan("");
  for (const AutoRun& a : autos)
    table.add_cells({std::string("auto07p"), fmt::format("NTST {}", a.ntst), double(a.ntst), nan,
                     0.1, double(a.points), a.seconds, 1e3 * a.seconds / a.points, a.max_error,
                     a.live ? 1.0 : 0.0, nan, nan, nan});
  for (const BackboneRun& b : runs)
    table.add_cells({std::string("backbone"),
                     b.label.empty() ? fmt::format("rtol {:g}, ds_max {:g}",
                                                   b.settings.relative_tolerance, b.settings.ds_max)
                                     : b.label,
                     nan, b.settings.relative_tolerance, b.settings.ds_max, double(b.points),
                     b.seconds, 1e3 * b.seconds / b.points, b.max_error, 1.0, double(b.residuals),
                     double(b.jacobians), b.cpu_seconds});
  return table;
}

// The headline: backbone's default settings against AUTO at NTST 50.
// auto50_paired: AUTO-07p NTST 50's median over the runs paired with the CLI defaults' (NaN:
// none; the table's NTST 50 run then stands in).
std::string headline_verdict(const BackboneSettings& headline, const std::vector<AutoRun>& autos,
                             const std::vector<BackboneRun>& runs, double auto50_paired) {
  const auto auto50 =
      std::find_if(autos.begin(), autos.end(), [](const AutoRun& a) { return a.ntst == 50; });
  const auto best = std::find_if(runs.begin(), runs.end(), [&](const BackboneRun& b) {
    return b.label.empty() && b.settings.relative_tolerance == headline.relative_tolerance &&
           b.settings.ds_max == headline.ds_max;
  });
  if (auto50 == autos.end() || best == runs.end())
    return "no AUTO-07p run at NTST 50 to compare with";
  const double ratio = best->seconds / auto50->seconds;
  std::string verdict = fmt::format(
      "backbone (rtol {:g}, ds_max {:g}) traces the backbone in {:.3g} s with error {:.2g}; "
      "AUTO-07p (NTST 50) takes {:.3g} s with error {:.2g}{}: time backbone / AUTO = {:.2f} "
      "at {} error.",
      headline.relative_tolerance, headline.ds_max, best->seconds, best->max_error, auto50->seconds,
      auto50->max_error, auto50->live ? " in the same run" : " (stored run)", ratio,
      best->max_error <= auto50->max_error ? "a smaller" : "a larger");
  const auto cli =
      std::find_if(runs.begin(), runs.end(), [](const BackboneRun& b) { return !b.label.empty(); });
  if (cli != runs.end()) {
    const bool paired = std::isfinite(auto50_paired);
    const double reference = paired ? auto50_paired : auto50->seconds;
    verdict += fmt::format(
        " At the command line's defaults (`trace problems/duffing/scenes/duffing.ini --bound "
        "amplitude:0.005:5`: {} points, a verified rank report and the multipliers at each) it "
        "takes {:.3g} s with error {:.2g}, AUTO-07p NTST 50 {:.3g} s{}: {:.2f} x AUTO-07p.",
        cli->points, cli->seconds, cli->max_error, reference,
        paired ? fmt::format(" (medians of {} alternating pairs)", paired_repetitions) : "",
        cli->seconds / reference);
  }
  return verdict;
}

void plot_duffing(const std::filesystem::path& csv, const std::filesystem::path& png) {
  const std::string q = core::gnuplot_quote(csv);
  const core::PlotResult plot = core::render_png(
      png,
      fmt::format(
          "set termoption noenhanced\nset logscale xy\nset grid\nset format y '%.0e'\nset datafile "
          "missing 'nan'\n"
          "set xlabel 'compute seconds, wall clock (one thread, median of 3; AUTO: its Total "
          "Time)'\n"
          "set ylabel 'max relative period error'\n"
          "set title 'Duffing backbone, amplitude 0.01 -> 5: work-precision'\n"
          "set key top right noenhanced\n"
          "plot {0} using (strcol(1) eq 'auto07p' ? $7 : NaN):9 with linespoints pt 7 ps 1.5 "
          "title 'AUTO-07p (NTST 20, 50)', "
          "{0} using (strcol(1) eq 'backbone' && $5 == 0.25 ? $7 : NaN):9 with linespoints pt 5 "
          "title 'backbone, ds_max 0.25 (rtol 1e-8 .. 1e-13)', "
          "{0} using (strcol(1) eq 'backbone' && $5 == 1 ? $7 : NaN):9 with linespoints pt 9 "
          "title 'backbone, ds_max 1 (rtol 1e-8 .. 1e-13)'\n",
          q));
  if (plot.ok)
    fmt::print("  wrote {}\n", png.string());
  else
    fmt::print("  figure skipped: {}\n", plot.message);
}

std::string duffing_section(const core::Table& table, const AutoRuns& autos,
                            const std::vector<BackboneRun>& runs, const std::string& verdict) {
  std::string rows;
  const std::vector<AutoRun>& a = autos.runs;
  for (std::size_t i = 0; i < table.rows(); ++i) {
    const bool is_auto = i < a.size();
    const double seconds = is_auto ? a[i].seconds : runs[i - a.size()].seconds;
    const double error = is_auto ? a[i].max_error : runs[i - a.size()].max_error;
    const int points = is_auto ? a[i].points : runs[i - a.size()].points;
    rows += fmt::format("| {} | {} | {} | {:.3g} | {:.3g} | {:.2g} |\n",
                        is_auto ? "AUTO-07p" : "backbone", table.text_column("setting")[i], points,
                        seconds, 1e3 * seconds / points, error);
  }
  return fmt::format(
      "## Duffing backbone: backbone vs AUTO-07p (`duffing_auto`)\n\n"
      "x'' + x + x^3 = 0 from amplitude 0.01 to 5. AUTO-07p 0.9.2 (orthogonal collocation, "
      "NCOL 4, DSMAX 0.1; input files in problems/duffing/bench/peers/) {}. backbone: shooting on "
      "the regular residual v(T/2) / v_max (CVODE Adams, Jacobian from the variational "
      "equations), pseudo-arclength from ds 0.5, eigen Newton to max(1e-11, rtol), no rank "
      "reports. Error: the largest |T - T_exact(A)| / T_exact(A) over the points, T_exact "
      "the elliptic integral (problems/duffing/README.md); AUTO's amplitude is taken from its "
      "energy, printed to 11 digits. Seconds: median of {}, wall clock of one thread (AUTO: "
      "its own Total Time of the periodic-orbit run; against stored runs, backbone's CPU "
      "time).\n\n"
      "| tool | setting | points | seconds | ms/point | max error |\n"
      "|---|---|---|---|---|---|\n{}\n"
      "**Where backbone stands:** {}\n\n![Duffing work-precision](duffing_auto.png)\n",
      autos.source, repetitions, rows, verdict);
}

}  // namespace

int bench_duffing_auto(const std::filesystem::path& out) {
  fmt::print(
      "bench duffing_auto: Duffing backbone x'' + x + x^3 = 0, amplitude 0.01 -> 5, backbone "
      "(shooting) vs AUTO-07p (collocation), errors vs the exact period\n");
  const BackboneSettings headline;
  const AutoRuns autos = auto07p_runs(headline);
  int status = 0;
  std::vector<BackboneRun> runs = run_sweep(backbone_sweep(headline), autos.live, status);
  // The command line's defaults against AUTO-07p NTST 50 in alternating pairs: both take a few
  // tens of ms, and a shared machine moves either by a third from run to run.
  double auto50_paired = std::nan("");
  {
    std::vector<double> seconds, cpu, auto_seconds;
    const std::filesystem::path scratch =
        std::filesystem::temp_directory_path() / fmt::format("backbone_auto07p_{}", ::getpid());
    BackboneRun run;
    for (int k = 0; k < paired_repetitions; ++k) {
      if (autos.live) {
        std::string why;
        if (const auto a = run_auto07p(50, headline.amplitude_end, scratch, why))
          auto_seconds.push_back(a->seconds);
      }
      run = trace_scene_defaults();
      seconds.push_back(run.seconds);
      cpu.push_back(run.cpu_seconds);
    }
    std::filesystem::remove_all(scratch);
    run.seconds = median(autos.live ? seconds : cpu);
    run.cpu_seconds = median(cpu);
    if (!auto_seconds.empty()) auto50_paired = median(auto_seconds);
    if (!run.complete) {
      fmt::print("  warning: the CLI defaults stopped early: {}\n", run.message);
      status = 1;
    }
    runs.push_back(run);
  }

  const core::Table table = duffing_table(autos.runs, runs);
  const std::filesystem::path csv = out / "duffing_auto.csv";
  table.write_csv(csv);
  fmt::print("{}", table.aligned(3));
  const std::string verdict = headline_verdict(headline, autos.runs, runs, auto50_paired);
  fmt::print("  {}\n", verdict);
  plot_duffing(csv, out / "duffing_auto.png");
  cli::write_bench_section(out, "duffing_auto", duffing_section(table, autos, runs, verdict));
  return status;
}

std::vector<cli::ProblemJob> bench_cases() {
  return {{"duffing_auto",
           "Duffing backbone vs AUTO-07p (live when installed): time and error vs the exact period",
           bench_duffing_auto}};
}

}  // namespace backbone::duffing
