// Options of a continuation run: a plain struct with defaults and a validate() naming the field.
//
// Step control follows the usual Newton-iteration heuristic (AUTO, BifurcationKit): after an
// accepted point ds grows by grow_factor when Newton needed at most fast_iterations, shrinks by
// shrink_factor when it needed at least slow_iterations; a failed correction shrinks ds and
// retries from the same point, and the branch ends with StopReason::step_floor once ds would
// fall below ds_min. Bounds end the branch when an observable leaves [min, max]; the last point
// is then re-corrected onto the bound itself (land_on_bounds, both methods). Distances are
// Euclidean in the unknowns divided by the problem's typical_scale() (scale_unknowns, the
// default: dimensionless, so one ds fits every scene of a problem): pseudo-arclength's ds, and
// the arclength column of both methods (sum of chords between consecutive points); natural
// continuation steps an unknown parameter by ds times its typical scale, an observable in its
// own units. `verification` also sets the verifier's corrector (core::VerifyOptions).
//
//   ContinuationOptions opt;
//   opt.ds = 0.01; opt.ds_max = 0.5; opt.max_points = 200;
//   opt.bounds.push_back({"energy", 0.0, 2550.0});
//   opt.rank_check_every = 5;   // verified rank report at every 5th point (0: never)
//   opt.validate();             // throws core::InputError("ds_min", "must be <= ds (...)")
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/rank/rank_report.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::continuation {

// Where the solution set ends: an observable that falls to 0 at its boundary (a nonsmooth edge,
// beyond which no solution exists or F cannot be evaluated). A branch that ends with step_floor
// or evaluation_failed at a point where the observable is at most `within` has reached that
// boundary: it ends with StopReason::boundary_reached, a planned end. Empty observable: none.
// With verify_inside (the followed families, branch_points/follow.hpp: each is traced whole from
// its point 0, never resumed), a rank check at such a point verifies the dimension just inside
// (internal/point_recorder.hpp, recheck_inside; DimensionFlag::inside).
struct Boundary {
  std::string observable;
  double within = 0;
  bool verify_inside = false;
};

// natural_then_arclength: natural until it stalls, then pseudo-arclength (switching.hpp).
enum class Method { natural, arclength, natural_then_arclength };
enum class Predictor { secant, tangent, quadratic };
const char* to_string(Method m);
const char* to_string(Predictor p);
Method parse_method(const std::string& name);        // InputError("method", ...)
Predictor parse_predictor(const std::string& name);  // InputError("predictor", ...)

// The branch ends when observable leaves [min, max].
struct Bound {
  std::string observable;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  // The scene keys the sides come from, for a start outside the bound: <observable>_min and
  // _max, `bound` (a NAME:MIN:MAX spec), a problem's own (the impact oscillator's wall_min and
  // wall_max); empty for a side a problem derives (the observable's name is said instead).
  std::string min_key = {}, max_key = {};
};

// Branch points (branch_points.hpp, continuation/README.md, section 'Branch points').
struct BranchPointOptions {
  bool detect = false;  // evaluate the test function, locate and verify candidates
  // Passing (always on, also without detect): a pseudo-arclength correction whose secant turns
  // by more than this from the predictor direction is refused like a failed one (ds shrinks), so
  // the step that lands on an attached family is retried; 0 disables the check.
  double max_turn_degrees = 20;
  // A sampled |tau_k| below dip_ratio times both neighbours is a candidate (besides sign changes).
  double dip_ratio = 0.5;
  // Location ends when the bracket is shorter than this (scaled arclength) or after
  // max_location_steps corrected points.
  double location_tolerance = 1e-9;
  int max_location_steps = 40;
  // Probes of candidate attached directions at a located point (each a corrected point).
  int max_probes = 24;
  // Their step (scaled units). Not the rank verification's (core::VerifyOptions::step, 1e-4):
  // a located point lies within ~1e-7 in period of the intersection, not on it, so its probes
  // step farther than the points' own verification does. On the contact bar at 100 intervals
  // the attached dimensions at T = 3.6 and 3.5 read 14 and 20 with 1e-4, 17 and 22 with 1e-3,
  // and the follow starts (the probe points) sit one step from the located point
  // (continuation/README.md, 'Branch points').
  double probe_step = 1e-3;
  // Locate and verify the candidates on a second thread while the loop goes on, when the
  // problem has a clone() (core/problem.hpp); else, or false, on the loop's thread. The rows are
  // the same bits either way (branch_points.hpp: BranchPointDetector::Locator).
  bool background = true;
  void validate() const;  // InputError naming branch_points.<field>
};

struct ContinuationOptions {
  Method method = Method::arclength;
  Predictor predictor = Predictor::tangent;
  // Pseudo-arclength: the first step follows the direction hint instead of the tangent at the
  // first point. For a start on a nonsmooth boundary of the solution set, where F has no
  // derivative and the finite-difference tangent mixes the two sides (the contact bar's
  // grazing limits: 8 to 83 degrees off the family, measured), or on a branch point, where the
  // Jacobian's null space holds the attached family too; with a hint that is the exact direction
  // of the family. Not passed on to followed families
  // (follow_attached).
  bool start_along_direction = false;
  double ds = 1e-2;      // first step
  double ds_min = 1e-8;  // below this the branch ends (step_floor)
  double ds_max = 1.0;
  // Adaptation on the Newton iteration count of the last accepted point.
  int fast_iterations = 3;     // grow when iterations <= this
  int slow_iterations = 8;     // shrink when iterations >= this
  double grow_factor = 1.5;    // > 1
  double shrink_factor = 0.5;  // in (0, 1); also used after a failed correction
  int max_points = 100;        // including the first (corrected guess)
  // Pseudo-arclength: each correction starts with chord steps on the factorization of the
  // previous point's Jacobian (bordered with the step direction), and each verification probe
  // with chord steps on the probed point's Jacobian; a fresh Jacobian only when a chord step
  // contracts too slowly (core/solvers/newton.hpp). The answer is judged by F alone.
  bool chord_corrections = true;
  // Both loops in z = x ./ typical_scale() (see scaled_problem.hpp): pseudo-arclength's ds and
  // both arclength columns in those units, natural steps of an unknown in units of its typical
  // scale; false: raw unknowns.
  bool scale_unknowns = true;
  std::vector<Bound> bounds;
  bool land_on_bounds = true;  // re-correct the crossing point onto the bound
  Boundary boundary;
  // Rank report of the problem's Jacobian at every k-th point (and always at the first and
  // last); 0 disables it. verify: also step along the candidate null directions.
  int rank_check_every = 1;
  bool verify = true;
  core::RankOptions rank;
  core::VerifyOptions verification;
  BranchPointOptions branch_points;
  // Floquet multipliers of every point when the problem is a core::FloquetProblem
  // (core/stability/floquet.hpp; branch.csv's stability columns, multipliers.csv).
  bool stability = true;
  core::FloquetOptions floquet;

  void validate() const;  // throws core::InputError naming the field
};

}  // namespace backbone::continuation
