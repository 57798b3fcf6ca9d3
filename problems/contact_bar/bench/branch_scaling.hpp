// What a whole mode-1 branch costs against the error it reaches (bench case mode1_scaling,
// bench.hpp): the mode-1 trace of the paper scene (scenes/paper.ini, `--branch mode1
// --start_offset 0.25 --energy_max 5e-3 --shooting_elements N`, T 3.8 -> 3.01; the exact-Jacobian
// study also from --start_offset 0.05, T 83/21 -> 3.01), run in-process as `backbone trace` runs
// it, once per setting (grid N, steps per period, formulation, corrector, threads, start). Each run
// is timed (process CPU and wall seconds), counted (points, Jacobians) and checked against
// ContactFamily's closed form at every point's own energy, as the trace's describe_point does.
// Beside it: the finite-difference Jacobian alone with 1 and 2 threads.
//
//   Mode1BranchSettings s;  s.elements = 40;  s.steps_per_period = 80;
//   const Mode1BranchCost c = trace_mode1_cost(s);    // c.points, c.cpu_seconds, c.worst_error
//   core::Table t = branch_cost_table({c});            // the columns of mode1_scaling.csv
//   double p = time_per_point_exponent(grid_runs, 40); // ms per point ~ N^p over N >= 40
//   JacobianThreadsTiming j = time_jacobian_threads(200);  // j.speedup(), j.identical
//   std::vector<int> n = parse_element_list("20, 40 80");   // {20, 40, 80}
#pragma once

#include <string>
#include <vector>

#include "core/io/table.hpp"
#include "core/types.hpp"

namespace backbone::contact_bar {

// One run of the mode-1 trace; every other key at the contact bar's trace default.
struct Mode1BranchSettings {
  std::string study = "grid";  // the row group of the table: grid, steps_per_period, ...
  int elements = 20;           // --shooting_elements
  int steps_per_period = 40;
  std::string formulation = "regular";   // or paper (scene key formulation)
  std::string newton = "eigen";          // or kinsol (square systems only: test_elements 0)
  int test_elements = -1;                // -1: the trace's auto (2x the unknowns)
  int threads = 1;                       // finite-difference Jacobian columns
  int rank_check_every = 1;              // --rank_check_every (0: no rank reports)
  double energy_max = 5e-3;              // [J]
  std::string jacobian = "differences";  // or exact (--jacobian)
  double start_offset = 0.25;            // --start_offset (0.25: T = 3.8, a branch point)
  bool stability = false;                // --stability (the multipliers of every point)
  // "N = 40", "steps_per_period = 80", "paper formulation", ...: the row's label.
  std::string label() const;
};

struct Mode1BranchCost {
  Mode1BranchSettings settings;
  bool complete = false;    // reached energy_max
  std::string stop_reason;  // continuation::to_string of the branch's StopReason
  std::string message;      // the branch's stop message
  int points = 0;
  long jacobians = 0;       // over the branch (BranchPoint::jacobian_evaluations summed)
  double cpu_seconds = 0;   // process CPU time of the continuation (all threads)
  double wall_seconds = 0;  // its wall time
  double worst_error = 0;   // max |omega / omega_exact(E) - 1| over the points
  double median_error = 0;
  double energy_reached = 0;           // the last point's energy [J]
  double sigma_zero = 0;               // the largest sigma_zero of the points' rank reports
  std::vector<core::Vector> unknowns;  // every point's x, to compare branches bit for bit

  double ms_per_point() const;  // CPU
  double jacobians_per_point() const;
};

// Throws core::InputError (naming the key) for a setting the trace refuses.
Mode1BranchCost trace_mode1_cost(const Mode1BranchSettings& settings);

// True when both branches have the same points, every unknown equal bit for bit.
bool same_branch(const Mode1BranchCost& a, const Mode1BranchCost& b);

// The rows of mode1_scaling.csv: study, setting, start_offset, N, steps_per_period, formulation,
// newton, test_elements, threads, points, jacobians_per_point, ms_per_point (CPU), total_seconds
// (CPU), wall_seconds, worst_closed_form_error, median_closed_form_error, energy_reached,
// complete (1 or 0), jacobian, sigma_zero_max.
core::Table branch_cost_table(const std::vector<Mode1BranchCost>& runs);

// Least-squares exponent p of ms_per_point ~ C N^p over the runs with N >= min_elements
// (log_log_slope). InputError "N" unless at least two such runs exist.
double time_per_point_exponent(const std::vector<Mode1BranchCost>& runs, int min_elements);

// "20,40,80" or "20 40 80": grids of at least 2 intervals, increasing; InputError(name)
// otherwise.
std::vector<int> parse_element_list(const std::string& text,
                                    const std::string& name = "BACKBONE_MODE1_SCALING_N");

// The finite-difference Jacobian (core::finite_difference_jacobian) of the mode-1 shooting
// residual at its first point (the closed-form orbit of the trace's start, end amplitude
// 1.25 g0) on a grid of `elements` intervals, with 1 and 2 threads, `repetitions` times each
// in alternation: the median wall and process CPU times, and whether both matrices are
// identical.
struct JacobianThreadsTiming {
  int elements = 0;
  int rows = 0, columns = 0;
  int repetitions = 0;
  double one_thread_seconds = 0, two_thread_seconds = 0;  // wall, median of the repetitions
  double one_thread_cpu = 0, two_thread_cpu = 0;          // process CPU, median
  bool identical = false;                                 // bit for bit
  double speedup() const { return one_thread_seconds / two_thread_seconds; }
};
JacobianThreadsTiming time_jacobian_threads(int elements, int repetitions = 21);

}  // namespace backbone::contact_bar
