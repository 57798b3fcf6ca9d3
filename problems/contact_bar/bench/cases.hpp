// The benchmarks of the contact bar: studies with known answers, not tests. Each case writes
// CSV tables and PNG figures into its output folder, prints its table and returns 0 (1 on a
// numerical failure it reports itself). The metrics they report are in bench_metrics.hpp.
//
//   tdbem_scaling      TD-BEM CPU time vs number of steps (mode 1, 10 periods): the slope of
//                      log(time) vs log(steps) should be 1 (O(1) work per step).
//   bouncing_bar       TD-BEM (projection, event) and FEM (Courant 1 and 0.9) against the
//                      closed-form bouncing bar over 10 periods: end displacement, contact
//                      force, energy drift, CPU time; plus the history figure (paper Fig. 3).
//   mode1_convergence  TD-BEM errors on the exact mode 1 (onset, release, force, return to u0)
//                      vs dt, with observed orders, for each contact method (FEM for reference).
//   formulations       the paper's shooting residual u0 - u(T) vs the regular half-period
//                      velocity one (problems/contact_bar/README.md) on the same exact orbits of
//                      modes 1 and 2 (4 amplitudes each): Newton from one perturbed start per
//                      orbit at fixed energy, iterations, observed orders, error to x*, exact-
//                      oracle return error and rank reports at the final point, residuals in
//                      metres whatever unit the problem uses.
//   mode1_scaling      mode 1 of the paper scene, T 3.8 -> 3.01, traced in-process over the
//                      grids N (BACKBONE_MODE1_SCALING_N, default 20,40,80,160,320,640), 80 steps
//                      per period, the paper formulation, kinsol and 2 threads: points,
//                      Jacobians and CPU ms per point, worst closed-form error, the exponent of
//                      ms per point over N >= 40; the FD Jacobian alone at N = 200 with 1 and 2
//                      threads (bench_branch_scaling.hpp).
//   branch_point_cost  mode 1 of the paper scene at 100 and 200 intervals to E = 1e-2, in-process,
//                      without branch-point detection, with it (candidates located on a second
//                      thread) and with it on the loop's thread, rounds alternated
//                      (BACKBONE_BRANCH_POINT_COST_RUNS, default 5): median wall and CPU seconds
//                      and what detection adds, candidates, verified ones and their periods'
//                      offsets from 3.6 / 3.5 / 3.25 / 3.2 L/c, the worst closed-form error.
//
//   for (const cli::ProblemJob& job : contact_bar::bench_cases())
//     if (job.name == "bouncing_bar") status = job.run("results/bench");
#pragma once

#include <filesystem>
#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::contact_bar {

// The six cases above, in that order (`backbone bench` runs them all).
std::vector<cli::ProblemJob> bench_cases();

// The cases one by one (what bench_cases() calls).
int bench_tdbem_scaling(const std::filesystem::path& out);
int bench_bouncing_bar(const std::filesystem::path& out);
int bench_mode1_convergence(const std::filesystem::path& out);
int bench_formulations(const std::filesystem::path& out);
int bench_mode1_scaling(const std::filesystem::path& out);
int bench_branch_point_cost(const std::filesystem::path& out);

}  // namespace backbone::contact_bar
