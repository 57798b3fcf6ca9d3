// A branch: the ordered points a continuation run corrected, and why it stopped.
//
// Every point carries its solution vector x (layout of the problem), the observables the problem
// reports there, the verified dimension of the solution set (rank report + re-correction along
// the candidate null directions, core/rank/rank_report.hpp), and the cost of getting it (Newton
// iterations, Jacobian and residual evaluations, wall seconds). A run that fails keeps every
// point corrected before the failure: the StopReason and message say why it ended. branch_table
// turns a branch into the columns of branch.csv (observables by name, then the bookkeeping
// columns): the deterministic ones only, so that a rerun writes the same file; the wall seconds
// are on the progress lines and in the bench cases.
//
//   Branch branch = pseudo_arclength(problem, start, direction, *newton, options, hooks);
//   if (branch.reason != StopReason::max_points) fmt::print("{}\n", branch.message);
//   for (const BranchPoint& p : branch.points) use(p.x, p.observable("energy"), p.dimension);
//   core::Table t = branch_table(branch);   // point, period, frequency, energy, ..., cost
//   t.write_csv(out / "branch.csv");
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/io/table.hpp"
#include "core/problem.hpp"
#include "core/rank/rank_report.hpp"
#include "core/stability/floquet.hpp"
#include "core/types.hpp"

namespace backbone::continuation {

struct LoopState;  // restart.hpp

// How a point's dimension was settled. Every point of a continuation curve has dimension >= 1
// (the curve passes through it), so a verified dimension of 0 contradicts the branch: the
// candidate probes failed (at an exact coincidence of the contact bar's time grid the candidate
// null space is several dimensions wide and none of its SVD directions re-corrects within the
// drift bound). It is then re-checked along the direction the continuation knows, the curve's
// tangent (or chord).
enum class DimensionFlag {
  as_verified = 0,  // the rank report's verified dimension, consistent with the curve
  rechecked = 1,    // below 1, re-checked: the tangent probe found the curve, dimension = 1 +
                    // the candidate directions orthogonal to it that verify
  unconfirmed = 2,  // below 1 and the tangent probe failed too: dimension as verified (0), not
                    // to be trusted
  inside = 3,       // on the boundary of its solution set (ContinuationOptions::boundary), where
                    // J is one side's: the dimension verified at a neighbour just inside
};

struct BranchPoint {
  int index = 0;                  // 0 for the corrected starting guess
  core::Vector x;                 // corrected solution, layout of the problem
  core::Observables observables;  // problem.observables(x)
  int dimension = -1;             // verified manifold dimension (-1: rank not checked here)
  DimensionFlag dimension_flag = DimensionFlag::as_verified;
  double residual = 0;  // ||F(x)||_inf of the problem (not of the augmented system)
  int newton_iterations = 0;
  double step_size = 0;  // the step ds that reached this point (0 for the first point)
  // Sum of the chords between consecutive points, Euclidean in the scaled unknowns
  // x ./ typical_scale() (options.scale_unknowns), the same units for every method.
  double arclength = 0;
  double seconds = 0;  // wall time spent on this point (prediction, correction, rank check)
  long jacobian_evaluations = 0;
  long residual_evaluations = 0;
  std::optional<core::RankReport> rank;  // when the rank was checked at this point
  // The orbit's Floquet multipliers, when the problem gives a monodromy (core::FloquetProblem)
  // and options.stability holds; undecided (stable = -1) where M could not be built.
  std::optional<core::Floquet> floquet;
  // The loop's state after this point (restart.hpp), what a restart from it needs to continue
  // bit for bit; null when the loop could not go on from it (e.g. a point landed on a bound).
  std::shared_ptr<const LoopState> state;

  // Value of a named observable; NaN when the problem does not report it.
  double observable(const std::string& name) const;
};

enum class StopReason {
  max_points,         // the requested number of points was reached
  bound_reached,      // an observable left its [min, max] window
  boundary_reached,   // the corrections stalled at the boundary of the solution set
                      // (ContinuationOptions::boundary)
  step_floor,         // Newton kept failing after shrinking ds to ds_min
  newton_failed,      // the very first point did not converge
  evaluation_failed,  // the residual returned NaN/Inf or failed where a point was needed
  singular_tangent,   // no well-defined tangent (null space of J not one-dimensional)
  cancelled,          // ContinuationHooks::cancel_requested returned true
};
const char* to_string(StopReason r);

// One line for a point whose dimension_flag is not as_verified (empty otherwise): what the
// verification gave and what the re-check along the curve found.
std::string dimension_warning(const BranchPoint& point);

// A candidate branch point located between two points of a branch (branch_points.hpp): where
// the test function changed sign or dipped. verified() when the rank report and its probes found
// more directions of solutions there than the traced tangent.
struct BranchPointReport {
  int after_point = 0;  // located between this point of the branch and the next one
  int bracket = -1;     // which of the branch's brackets, from 0 (BranchPointDetector::brackets)
  core::Vector x;       // located point, problem's unknowns
  core::Observables observables;  // problem.observables(x)
  double arclength = 0;           // along the branch, same units as BranchPoint::arclength
  double test_value = 0;          // signed test function at x (branch_points.hpp)
  bool sign_change = false;       // bracketed by a sign change (else by a dip)
  int location_steps = 0;         // corrected points spent locating it
  // The problem's Jacobians and residuals spent locating and verifying it (its counters).
  long jacobian_evaluations = 0, residual_evaluations = 0;
  int nullity = -1;  // candidate null directions of J at x (rank report)
  // Candidate directions beyond the traced tangent along which a probe found solutions (at most
  // options.branch_points.max_probes probed): the dimension of the attached family at this
  // resolution; verified_dimension = 1 + attached_dimension (the traced tangent counted).
  int attached_dimension = 0;
  // Candidate directions beyond the tangent, and how many were probed (at most
  // BranchPointOptions::max_probes): with fewer probed, attached_dimension is a lower bound.
  int candidates = 0, probed = 0;
  int verified_dimension = -1;
  // Angle [degrees] between the traced tangent and the closest secant to a probed point of the
  // attached family (90: it leaves at right angles); NaN when none was found.
  double tangent_angle = 0;
  core::Vector attached_point;  // that probed point (unknowns), empty when none
  // Every probed point found on the attached family (unknowns), in the order of the probed
  // directions; attached_point is one of them (continuation/branch_points/follow.hpp switches onto
  // one).
  std::vector<core::Vector> attached_points;
  core::Observables attached_description;  // ContinuationHooks::describe_branch_point
  double seconds = 0;                      // wall time of location and verification
  bool verified() const { return attached_dimension > 0; }
};

struct Branch {
  std::vector<BranchPoint> points;
  // Candidate branch points located along the branch (options.branch_points.detect), in order.
  std::vector<BranchPointReport> branch_points;
  StopReason reason = StopReason::max_points;
  std::string message;  // human-readable: reason, the point and the numbers involved
  // A resumed run: branch_points holds the candidates with after_point >= this (the earlier
  // run's rows below it stand; write_after_run merges them); -1 when the run did not resume.
  int branch_points_from = -1;
  // Converged corrections refused (hooks.reject_point, the arclength loop's turn check) while
  // tracing it, a resumed run's earlier ones included (LoopState::rejected_corrections).
  int rejected_corrections = 0;
  // True when the branch ended for a reason other than reaching its planned end
  // (max_points, a bound, or the boundary of the solution set).
  bool ended_early() const {
    return reason != StopReason::max_points && reason != StopReason::bound_reached &&
           reason != StopReason::boundary_reached;
  }
};

// Columns: point, then every observable by name (in the order of the first point), then, when
// the first point has multipliers, stable (1, 0, -1 undecided), unstable_multipliers,
// max_multiplier_modulus (non-trivial ones), trivial_multiplier_distance (largest |mu - 1| of the
// trivial ones) and monodromy_determinant, then dimension, dimension_flag (DimensionFlag: 0 as
// verified, 1 re-checked along the tangent, 2 below the curve's 1 and unconfirmed), nullity
// (candidate, -1 when unchecked), sigma_zero and sigma_kept (largest singular value counted as zero
// and smallest kept, relative to the largest), residual, newton_iterations, step_size, arclength,
// jacobian_evaluations, residual_evaluations. Repeated runs write it bit for bit: it holds no wall
// time.
core::Table branch_table(const Branch& branch);

// multipliers.csv: one row per point and multiplier (points with multipliers only): point, index
// (by decreasing modulus), re, im, modulus, trivial (1: counted as a trivial multiplier).
core::Table multiplier_table(const Branch& branch);

// branch_points.csv: one row per located candidate (Branch::branch_points): its observables (the
// names of template_point first, e.g. a point of the branch, so that an empty list still has
// them), dimension (of the attached family, 0 when not verified), the problem's description
// columns (ContinuationHooks::describe_branch_point, e.g. frequency_ratio), tangent_angle
// [degrees], verified (0/1), nullity (candidate directions at the point), after_point, arclength,
// test_value, sign_change (0/1: located as a root, else as a dip's minimum), location_steps,
// jacobian_evaluations, residual_evaluations (location and verification).
core::Table branch_point_table(const Branch& branch, const core::Observables& template_point = {});

}  // namespace backbone::continuation
