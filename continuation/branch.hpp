// A branch: the ordered points a continuation run corrected, and why it stopped.
//
// Every point carries its solution vector x (layout of the problem), the observables the problem
// reports there, the verified dimension of the solution set (rank report + re-correction along
// the candidate null directions, core/rank_report.hpp), and the cost of getting it (Newton
// iterations, Jacobian evaluations, wall seconds). A run that fails keeps every point corrected
// before the failure: the StopReason and message say why it ended. branch_table turns a branch
// into the columns of branch.csv (observables by name, then the bookkeeping columns).
//
//   Branch branch = pseudo_arclength(problem, start, direction, *newton, options, hooks);
//   if (branch.reason != StopReason::max_points) fmt::print("{}\n", branch.message);
//   for (const BranchPoint& p : branch.points) use(p.x, p.observable("energy"), p.dimension);
//   core::Table t = branch_table(branch);   // point, period, frequency, energy, ..., seconds
//   t.write_csv(out / "branch.csv");
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/rank_report.hpp"
#include "core/table.hpp"
#include "core/types.hpp"

namespace backbone::continuation {

struct BranchPoint {
  int index = 0;                  // 0 for the corrected starting guess
  core::Vector x;                 // corrected solution, layout of the problem
  core::Observables observables;  // problem.observables(x)
  int dimension = -1;             // verified manifold dimension (-1: rank not checked here)
  double residual = 0;            // ||F(x)||_inf of the problem (not of the augmented system)
  int newton_iterations = 0;
  double step_size = 0;  // ds used to reach this point (0 for the first point)
  // Sum of the chords between consecutive points, Euclidean in the scaled unknowns
  // x ./ typical_scale() (options.scale_unknowns), the same units for every method.
  double arclength = 0;
  double seconds = 0;  // wall time spent on this point (prediction, correction, rank check)
  long jacobian_evaluations = 0;
  long residual_evaluations = 0;
  std::optional<core::RankReport> rank;  // when the rank was checked at this point

  // Value of a named observable; NaN when the problem does not report it.
  double observable(const std::string& name) const;
};

enum class StopReason {
  max_points,         // the requested number of points was reached
  bound_reached,      // an observable left its [min, max] window
  step_floor,         // Newton kept failing after shrinking ds to ds_min
  newton_failed,      // the very first point did not converge
  evaluation_failed,  // the residual returned NaN/Inf or failed where a point was needed
  singular_tangent,   // no well-defined tangent (null space of J not one-dimensional)
  cancelled,          // ContinuationHooks::cancel_requested returned true
};
const char* to_string(StopReason r);

struct Branch {
  std::vector<BranchPoint> points;
  StopReason reason = StopReason::max_points;
  std::string message;  // human-readable: reason, the point and the numbers involved
  // True when the branch ended for a reason other than reaching its planned end
  // (max_points or a bound).
  bool ended_early() const {
    return reason != StopReason::max_points && reason != StopReason::bound_reached;
  }
};

// Columns: point, then every observable by name (in the order of the first point), then
// dimension, nullity (candidate, -1 when unchecked), sigma_zero and sigma_kept (largest
// singular value counted as zero and smallest kept, relative to the largest), residual,
// newton_iterations, step_size, arclength, seconds, jacobian_evaluations, residual_evaluations.
core::Table branch_table(const Branch& branch);

}  // namespace backbone::continuation
