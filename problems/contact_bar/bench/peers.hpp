// The contact bar beside its peers: two benchmark cases that put backbone's own runs, measured
// live, next to the stored measurements of problems/contact_bar/bench/peers/ (README.md there:
// provenance), each writing a CSV, a work-precision PNG and its section of BENCHMARKS.md
// (continuation/cli/bench_report.hpp).
//
//   lu_legrand   mode 1 of the paper scene from T = 3.8 to 3.01 (end amplitude 1.25 g0 up to
//                E = 5e-3 J), traced as `backbone trace` does at several shooting grids N,
//                against Lu & Legrand's frequency-domain BEM + harmonic balance (20 and 40
//                harmonics): ms per point against the median relative frequency error, both
//                measured against the closed form at each point's own energy.
//   siconos_bar  the Siconos bar (mode 1 with eps = -0.002, T = 3.5) over 10 time units at
//                dt = 1e-3, TD-BEM (event contact) at 50, 100 and 200 elements against
//                Siconos' Moreau-Jean time stepping: us per step against the tip error.
//
//   Mode1Trace t = trace_paper_mode1(20);          // t.points, t.seconds, t.median_error
//   for (const cli::ProblemJob& job : peer_bench_cases()) job.run("results/bench");
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::contact_bar {

// One trace of mode 1 on the paper scene (scenes/paper.ini, --start_offset 0.25 --energy_max
// 5e-3 --shooting_elements N, every other key at its trace default), timed in-process.
struct Mode1Trace {
  int elements = 0;
  bool complete = false;  // reached energy_max
  int points = 0;
  double seconds = 0;       // wall time of the continuation
  double median_error = 0;  // |omega / omega_exact(E) - 1| over the points
  double max_error = 0;
  std::string message;  // the branch's stop message
};
Mode1Trace trace_paper_mode1(int shooting_elements);

// The folder of the stored peer data (problems/contact_bar/peers).
std::filesystem::path contact_bar_peers_folder();

int bench_lu_legrand(const std::filesystem::path& out);
int bench_siconos_bar(const std::filesystem::path& out);

// {lu_legrand, siconos_bar}: appended to bench_cases() by the plugin.
std::vector<cli::ProblemJob> peer_bench_cases();

}  // namespace backbone::contact_bar
