#include "problems/contact_bar/bench/cases.hpp"

namespace backbone::contact_bar {

std::vector<cli::ProblemJob> bench_cases() {
  return {
      {"tdbem_scaling", "TD-BEM CPU time vs number of steps (slope 1 = O(1) per step)",
       bench_tdbem_scaling},
      {"bouncing_bar", "TD-BEM and FEM against the closed-form bouncing bar (work-precision)",
       bench_bouncing_bar},
      {"mode1_convergence", "TD-BEM and FEM errors on the exact mode 1 vs dt, observed orders",
       bench_mode1_convergence},
      {"formulations", "regular vs paper shooting residual, Newton from perturbed exact orbits",
       bench_formulations},
      {"mode1_scaling",
       "mode 1 branch cost vs closed-form error over N, steps per period, formulation, "
       "corrector and threads; the FD Jacobian with 1 and 2 threads",
       bench_mode1_scaling},
      {"branch_point_cost",
       "what branch-point detection adds to the mode-1 trace at 100 and 200 intervals (wall and "
       "CPU, "
       "second thread or not) against the located periods' accuracy",
       bench_branch_point_cost},
  };
}

}  // namespace backbone::contact_bar
