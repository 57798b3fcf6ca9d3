// Restarting a traced branch: the state a continuation loop holds between two points, saved with
// every accepted point, and how a run takes up a saved point (`trace --resume DIR`, `trace
// --start DIR:K`; the COCO habit: every run can be restarted from any saved point).
//
// LoopState is everything the loop of pseudo_arclength (or natural) needs to take its next step:
// the point z and its unit tangent in the scaled unknowns, the point before it (secant
// predictor), the step the next point is tried with, the natural parameter's value and last
// step, the branch-point detector's samples, the index and arclength. A loop continued from it
// (pseudo_arclength(problem, state, ...)) takes exactly the steps the uninterrupted run took,
// bit for bit: nothing is re-corrected or re-derived. BranchWriter (outputs.hpp) writes it as one
// line of state.txt per point, every number in shortest round-trip form (format_state; read back
// by parse_state; format: continuation/README.md, section 'Restart files').
//
//   RestartPoint r = restart_point(out, -1, "resume");   // the last point; r.state when saved
//   r.record_saved_point = false;                         // --resume: it is in the files already
//   take_up(r, "resume", +1, problem, options, guess, direction);
//   SwitchingBranch b = run_continuation(problem, guess, direction, run, corrector, hooks, &r);
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "continuation/branch_points/branch_points.hpp"
#include "continuation/options.hpp"
#include "core/problem.hpp"
#include "core/types.hpp"

namespace backbone::continuation {

// Where a loop begins when it starts from a guess: the index and arclength of its first point
// (a branch continued from a saved point without its state, or the arclength part of
// natural_then_arclength, numbers its points on from there) and the switch index its states
// carry.
struct BranchStart {
  int index = 0;
  double arclength = 0;
  int switch_index = -1;
  int rejected_corrections = 0;  // refused before this start (Branch::rejected_corrections)
};

// A point of the branch seen before a restart: index, arclength and observables.
struct KnownPoint {
  int index = 0;
  double arclength = 0;
  core::Observables observables;
};

struct LoopState {
  Method method = Method::arclength;  // the loop it continues: arclength or natural
  int index = 0;                      // the point's index on the branch
  double arclength = 0;               // the point's arclength
  // ScaledProblem::scale() of the run (z = x ./ scale): a state is taken up only by a run with
  // the same scale, bit for bit (same scene and grid); x = z .* scale.
  core::Vector scale;
  core::Vector z;         // the point, scaled unknowns
  core::Vector tangent;   // arclength: unit tangent at z, oriented along the branch
  core::Vector previous;  // the point before z (secant predictors); empty when unused
  // Arclength with chord corrections: the problem's unknowns (not z) where the Jacobian the
  // next correction starts from was computed; empty: a fresh Jacobian (scaled_problem.hpp,
  // jacobian_at_unknowns).
  core::Vector jacobian_point;
  int chord_misses = 0;  // corrections since a chord on it last helped (pseudo_arclength.cpp)
  int rejected_corrections = 0;  // Branch::rejected_corrections up to this point
  double ds = 0;                 // the step the next point is tried with
  double lambda = 0;             // natural: the parameter's value at z (its row's value)
  double previous_step = 0;      // natural: the parameter step that reached z (0: none)
  int switch_index = -1;         // natural_then_arclength: first arclength point, -1 before
  double jacobian_scale = 0;     // branch-point detector: its Jacobian scale (0: unset)
  std::vector<TestFunctionSample> samples;  // the detector's samples before z was added
  // Branch-point detector: the candidates it had bracketed before z was added (-1: not saved).
  // A resume from this state brackets again from there on; the candidates located earlier must
  // come from the saved list (SavedBranchPoints below).
  int brackets = -1;
  // Not in the text form: the saved point and the one before it as the files hold them, which a
  // resumed loop looks back on where an uninterrupted one has its last two points (the chord
  // that aims a step at a bound ahead, LoopSteps::bound_within). Filled by take_up.
  std::vector<KnownPoint> known_points;

  core::Vector unknowns() const { return z.cwiseProduct(scale); }
};

// One line (no newline, no point number): `name=value` tokens separated by spaces, vectors as
// comma-separated values. parse_state reads it back exactly; InputError naming `key` on any
// defect (`where` names the file and point in the message).
std::string format_state(const LoopState& state);
LoopState parse_state(const std::string& line, const std::string& key, const std::string& where);

// Where a restarted run takes up a saved point. With `state` (state.txt holds the point's loop
// state) the run continues from it bit for bit; without it (an older folder, a point landed on a
// bound, another scene's scale) the saved unknowns x are corrected again, the branch going along
// the secant from the point before (empty at point 0), with the step the uninterrupted run would
// take next (adapted_step of the point's own step and Newton iterations; 0 at point 0: use ds).
struct RestartPoint {
  int index = 0;
  double arclength = 0;
  core::Vector x;
  core::Vector secant;
  double next_step = 0;
  std::shared_ptr<const LoopState> state;
  // true: the saved point is the first point of the restarted branch (--start into a new
  // folder); false: it is not reported again (--resume: it is in the files).
  bool record_saved_point = true;
  std::string note;         // why the state was not used (take_up), empty otherwise
  core::Vector previous_x;  // the point before (empty at point 0) and its arclength
  double previous_arclength = 0;
  // Corrections refused on the saved branch up to the point: its state's count, else that of
  // the last state saved before it (0 without one); BranchStart::rejected_corrections of a
  // restart without a state.
  int rejected_corrections = 0;
  // --resume of a run killed or stopped after its loop had reached max_points (summary.txt says
  // "running" or "interrupted"): no point is left to trace, the run redoes only what follows the
  // loop (outputs, stability, follows).
  bool loop_complete = false;
};

// "DIR:K" or "DIR/orbits.csv:K" (any file of DIR) -> (DIR, K); InputError naming `key`.
std::pair<std::filesystem::path, int> parse_saved_point(const std::string& text,
                                                        const std::string& key);
// Point `point` (-1: the last one) of the branch in `dir` (branch.csv, unknowns.csv, state.txt
// when present). InputError naming `key` when the folder lacks the files or the point.
RestartPoint restart_point(const std::filesystem::path& dir, int point,
                           const ContinuationOptions& options, const std::string& key);

// Why `state` cannot continue a run of `problem` with `options` (another size, scale or method),
// empty when it can. loop: the loop that would take it up (natural or arclength); without it,
// the one options.method runs from that state.
std::string state_mismatch(const LoopState& state, const core::Problem& problem,
                           const ContinuationOptions& options);
std::string state_mismatch(const LoopState& state, const core::Problem& problem,
                           const ContinuationOptions& options, Method loop);

// Makes a run start from the saved point. direction -1 turns back: the state's tangent is
// reversed and its secant and detector samples dropped (a new path from that point), the
// fallback's secant reversed. A state that does not fit (state_mismatch) is dropped, its reason
// in restart.note. Without a state: guess = x, direction = the secant (when saved), ds = the next
// step within [ds_min, ds_max]. InputError naming `key` when the guess's size differs (another
// grid), or naming max_points when no point would be left (max_points counts the whole branch)
// and the saved run's loop is not known to have ended there (RestartPoint::loop_complete).
void take_up(RestartPoint& restart, const std::string& key, int direction,
             const core::Problem& problem, ContinuationOptions& options, core::Vector& guess,
             core::Vector& hint);

// The located candidates of a detecting run, kept while it runs so that an interrupted run
// loses none: trace rewrites out/branch_points.txt (atomically) whenever a candidate is located
// or a bracket settles (ContinuationHooks::on_branch_point, on_brackets_settled), while
// branch_points.csv is written once the branch has ended. Format (continuation/README.md,
// 'Restart files'): a header line, `settled=N`, then one line per candidate of `name=value`
// tokens, every number in its shortest round-trip form. Repeated runs write it bit for bit: it
// holds no wall time (BranchPointReport::seconds reads back as 0).
struct SavedBranchPoints {
  int settled = 0;  // brackets located or given up: the list is complete below this bracket
  std::vector<BranchPointReport> reports;  // in bracket order (BranchPointReport::bracket)
  // Writes out/branch_points.txt atomically; std::runtime_error when it cannot.
  void write(const std::filesystem::path& out) const;
};
// Reads dir/branch_points.txt (the observables recomputed by problem.observables). InputError
// naming `key` on any defect.
SavedBranchPoints read_saved_branch_points(const std::filesystem::path& dir,
                                           const core::Problem& problem, const std::string& key);

// Where a resumed detecting run takes up its branch so that it loses no candidate. Location runs
// behind the loop (branch_points.hpp), so when a run is killed the candidates bracketed by its
// last points may still be being located: branch_points.txt then holds fewer brackets than the
// last state had made. The resume starts from the last point `point` <= last whose state had
// made at most the settled brackets (LoopState::brackets); the run from there is the
// interrupted one's bit for bit and brackets the rest again. saved: the candidates bracketed
// before that point. Empty when dir has no branch_points.txt, when a state on the way back does
// not count brackets, or when none had made few enough (the rows of branch_points.csv are then
// merged as write_after_run says). The caller checks that the point's state fits its run.
struct BranchPointResume {
  int point = 0;
  SavedBranchPoints saved;
};
std::optional<BranchPointResume> branch_point_resume(const std::filesystem::path& dir, int last,
                                                     const core::Problem& problem,
                                                     const std::string& key);

}  // namespace backbone::continuation
