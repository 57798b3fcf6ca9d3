// Following attached families: switch onto the family that attaches at a verified branch point
// of a traced branch and trace a branch in it (continuation/README.md, section 'Following
// attached branches').
//
// At a located branch point x the probes of branch_points.hpp found points y_i of the attached
// family, one per verified null direction orthogonal to the traced tangent. The switch takes the
// probe along which the chosen observable (energy) changes fastest per unit of scaled distance,
// |f(y_i) - f(x)| / |y_i - x|, and the sign of that change: the branch starts at
// x + sign (y_i - x) (corrected on the hyperplane orthogonal to that direction, which misses the
// traced branch near x) and leaves in the direction sign (y_i - x), so the observable grows. In
// an attached family of more than one dimension the pseudo-arclength loop then keeps each tangent
// as the previous one projected on the null space (pseudo_arclength.hpp): the path turns as
// little as the family allows, starting along the steepest verified direction.
//
//   const FollowSelection which = parse_follow("all");             // or "none", "2"
//   ContinuationOptions o = options; o.max_points = 30;             // the follow_max_points budget
//   for (int k = 1; k <= int(branch.branch_points.size()); ++k)
//     if (which.selects(k)) {
//       FollowedBranch f = follow_attached(problem, branch.branch_points[k - 1], "energy",
//                                          corrector, o, hooks);   // hooks.reject_point applies
//       use(f.branch.points, f.start_probe, f.message);
//     }
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation {

// Which branch points to follow (scene key `follow`): none, all verified ones, or the K-th row of
// branch_points.csv (1-based, every located candidate counted, verified or not; an unverified
// K-th is reported and not followed).
struct FollowSelection {
  enum class Kind { none, all, one };
  Kind kind = Kind::none;
  int k = 0;  // with Kind::one
  // Also switch at every period doubling of the orbits (bifurcations.csv; "all" or "doubling",
  // the latter without branch points).
  bool doublings = false;
  bool selects(int one_based) const {
    return kind == Kind::all || (kind == Kind::one && one_based == k);
  }
};
// "none", "all", "doubling" or a positive integer; InputError naming `follow` otherwise.
FollowSelection parse_follow(const std::string& text);

// Where a followed branch starts: the guess (unknowns), the direction hint, the probe chosen.
struct AttachedStart {
  core::Vector guess, direction;
  int probe = -1;     // index in BranchPointReport::attached_points
  double growth = 0;  // |f(y) - f(x)| / |y - x| (scaled distance) of that probe
};
// Distances in the loop's scaled unknowns (scaled_problem.hpp). rank 0: the probe along which
// the observable changes fastest, 1 the next one, ... Empty when the report has no such probe
// (none probed, or the observable NaN at them).
std::optional<AttachedStart> attached_start(const core::Problem& problem,
                                            const BranchPointReport& report,
                                            const std::string& observable, int rank = 0);

struct FollowedBranch {
  int branch_point = 0;  // K, 1-based (row of branch_points.csv)
  std::optional<AttachedStart> start;
  Branch branch;        // empty points when it could not start
  std::string message;  // why it did not start, else the branch's own message
  int attempts = 1;     // starts tried (follow_branch_points retries a branch that ended early)
};

// The turn check of a followed branch (ContinuationOptions::branch_points.max_turn_degrees is
// raised to it; 0, off, stays off). An attached family may have corners: the contact bar's are
// piecewise affine in u0 for a fixed contact sequence, and where the path meets an edge the
// forward-difference Jacobian straddles it, so every retried step turns by the corner's angle
// whatever ds is (measured at 100 intervals, T = 3.5 L/c: 20.5-22.4 degrees down to ds_min, the
// followed branch ended at the step floor; the traced branch's 20 degrees refused them). The
// steps that jump across the family turn by 75-90 degrees (measured on the same branches): 45
// degrees, a correction as long as the step, keeps those refused and lets the path turn a
// corner.
inline constexpr double follow_max_turn_degrees = 45;

// Pseudo-arclength (detection off) from attached_start(report) with `options` (bounds, step
// control, the max_points budget; the turn check raised to follow_max_turn_degrees) and `hooks`
// (reject_point: the per-point check applies to every orbit of the followed branch). Never throws
// on numerical failure.
FollowedBranch follow_attached(const core::Problem& problem, const BranchPointReport& report,
                               const std::string& observable, core::Corrector& corrector,
                               const ContinuationOptions& options,
                               const ContinuationHooks& hooks = {}, int start_rank = 0);

// What `backbone trace --follow` does after the traced branch: every selected point of
// branch.branch_points followed by follow_attached with max_points = max_points and the rank
// report at every 10th point at most (plus the first and last), each into
// out/branch_point_K/ (BranchWriter files, branch.png, then extra(dir, followed branch) when
// set; an unverified K-th gets only summary.txt saying why). A followed branch that ends early
// (e.g. at the step floor) is retried from the next fastest probe, at most start_attempts starts
// in all; the files hold the last attempt. periodic: the problem when it is a
// periodic-orbit problem (orbits.csv), else nullptr.
struct FollowRun {
  FollowSelection selection;
  int max_points = 30;
  std::string observable = "energy";
  int start_attempts = 3;
};
// The corrector settings for following: the rank cut-off raised to the rank report's relative
// threshold. In an attached family of dimension d the bordered Jacobian has d - 1 singular
// values at the finite-difference noise (1e-8..1e-6 relative at the contact bar's T = 3.5 and
// 3.6 L/c, d = 19-24): a cut-off below them divides by noise, and the minimum-norm step jumps
// across the family (measured: every step turned by 90 degrees, the branch ended after 6 and 12
// points; with the cut-off, 30 of 30).
core::NewtonOptions follow_newton_options(const core::NewtonOptions& newton,
                                          const ContinuationOptions& options);

// Follows the selected rows of branch.branch_points into out/branch_point_K/. A stop request
// (hooks.cancel_requested) ends the branch under way and leaves the rows after it untouched.
std::vector<FollowedBranch> follow_branch_points(
    const core::Problem& problem, const Branch& branch, const FollowRun& run,
    core::Corrector& corrector, const ContinuationOptions& options, const ContinuationHooks& hooks,
    const std::filesystem::path& out,
    const std::function<void(const std::filesystem::path&, const Branch&)>& extra = {},
    const std::map<std::string, std::string>& units = {});

// One line per followed branch for the console: "branch point K: N points, OBSERVABLE in [a, b],
// period varies by r (relative; NaN without a period observable), stop reason (message)".
std::string follow_line(const FollowedBranch& f, const std::string& observable = "energy");

}  // namespace backbone::continuation
