// The Duffing benchmark against AUTO-07p: the conservative backbone x'' + x + x^3 = 0 from
// amplitude 0.01 to 5, traced by backbone (shooting, pseudo-arclength) and by AUTO-07p
// (orthogonal collocation), both timed in the same run, both errors measured against the exact
// period (exact_period, the elliptic-integral oracle). AUTO runs live when it is installed
// (Debian packages auto-07p, gfortran, make); otherwise the case says so and uses the stored
// runs of problems/duffing/bench/peers/ (README.md there: provenance).
//
//   BackboneSettings s;  s.relative_tolerance = 1e-12;        // one backbone run
//   BackboneRun b = trace_backbone(s);                          // b.points, b.seconds, b.max_error
//   std::string why;
//   if (auto07p_available(why)) {
//     std::optional<AutoRun> a = run_auto07p(50, 5.0, "/tmp/auto_duffing", why);
//   }
//   int status = bench_duffing_auto("results/bench");           // `backbone bench --case
//   duffing_auto`
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::duffing {

// One backbone trace of the benchmark (pseudo-arclength, tangent predictor, eigen Newton, the
// regular formulation).
struct BackboneSettings {
  double relative_tolerance = 1e-12;  // CVODE rtol (DuffingOptions)
  double ds = 0.5;                    // first step (dimensionless, continuation/options.hpp)
  double ds_max = 1.0;                // largest step
  double newton_tolerance = 1e-11;    // ||F||_inf, F = v(T/2) / v_max: dT / T <= F / 3
  double amplitude_start = 0.01;
  double amplitude_end = 5.0;
  int rank_check_every = 0;  // 0: no rank reports (the backbone is a known curve)
};

struct BackboneRun {
  BackboneSettings settings;
  bool complete = false;  // reached amplitude_end
  int points = 0;
  double seconds = 0;      // wall time of the continuation (one thread)
  double cpu_seconds = 0;  // process CPU time of the same
  double max_error = 0;    // max over points |T - T_exact(x0)| / T_exact(x0)
  long residuals = 0;
  long jacobians = 0;
  std::string message;  // the branch's stop message
  std::string label;    // the table's setting (empty: rtol and ds_max of settings)
};

// Throws InputError for bad settings; a numerical failure is complete = false.
BackboneRun trace_backbone(const BackboneSettings& settings);

// The command line's defaults: `backbone trace problems/duffing/scenes/duffing.ini --bound
// amplitude:0.005:5` (the scene's rtol, steps and Newton settings, a verified rank report and
// the multipliers at every point), the continuation alone timed (no output files, no figure).
BackboneRun trace_scene_defaults();

// One AUTO-07p run of the stored input files (peers/duffing.f90, peers/duffing.auto).
struct AutoRun {
  int ntst = 0;
  bool live = false;  // measured in this run (false: stored peer data)
  int points = 0;
  double seconds = 0;    // AUTO's "Total Time" of the periodic-orbit run (its own clock)
  double max_error = 0;  // max |T - T_exact(A_H)| / T_exact(A_H), A_H from AUTO's energy H
};

// True when AUTO-07p's Python driver, gfortran and make are installed; else why not.
bool auto07p_available(std::string& why);
// Runs AUTO-07p with NTST = ntst up to amplitude amax in `folder` (created; AUTO compiles
// duffing.f90 there once). nullopt with the reason in `why` when the run fails.
std::optional<AutoRun> run_auto07p(int ntst, double amax, const std::filesystem::path& folder,
                                   std::string& why);
// The stored peer runs (peers/auto07p_runs.csv and the backbone CSVs); InputError when absent.
std::vector<AutoRun> stored_auto07p_runs();

// Maximum relative period error of AUTO's branch file b.duffing (points of positive energy).
// InputError ("b.duffing") when it holds no periodic-orbit point.
AutoRun read_auto07p_branch(const std::filesystem::path& branch_file);

// The folder of the stored AUTO-07p input files and runs (problems/duffing/bench/peers).
std::filesystem::path peers_folder();

// `backbone bench --case duffing_auto`: the work-precision table (backbone at several CVODE
// tolerances and step caps, AUTO at NTST 20 and 50), duffing_auto.csv, duffing_auto.png and the
// section duffing_auto.md of BENCHMARKS.md.
int bench_duffing_auto(const std::filesystem::path& out);

std::vector<cli::ProblemJob> bench_cases();

}  // namespace backbone::duffing
