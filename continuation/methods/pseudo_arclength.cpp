#include "continuation/methods/pseudo_arclength.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "continuation/branch_points/branch_points.hpp"
#include "continuation/internal/loop_steps.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "core/solvers/bordered_system.hpp"
#include "core/solvers/eigen_newton.hpp"

namespace backbone::continuation {

core::EvalStatus curve_tangent(const core::Problem& problem, const core::Vector& x,
                               const core::Vector& orientation, double relative_threshold,
                               core::Vector& tangent) {
  core::Matrix J;
  core::EvalStatus s = problem.jacobian(x, J);
  if (s != core::EvalStatus::ok) return s;
  return tangent_from_jacobian(J, orientation, relative_threshold, tangent);
}

core::EvalStatus tangent_from_jacobian(const core::Matrix& J, const core::Vector& orientation,
                                       double relative_threshold, core::Vector& tangent) {
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  core::Matrix bordered(m + 1, n);
  bordered.topRows(m) = J;
  bordered.row(m) = orientation.normalized().transpose();
  core::Vector rhs = core::Vector::Zero(m + 1);
  rhs[m] = 1.0;
  // The minimum-norm solution (core::minimum_norm_solve: a plain QR where the bordered matrix
  // has full rank by a wide margin, else the rank-revealing complete orthogonal decomposition,
  // its threshold relative to the largest pivot, like the rank report's).
  core::minimum_norm_solve(bordered, rhs, relative_threshold, tangent);
  const double norm = tangent.norm();
  if (!std::isfinite(norm) || norm == 0) return core::EvalStatus::non_finite;
  tangent /= norm;
  if (tangent.dot(orientation) < 0) tangent = -tangent;
  return core::EvalStatus::ok;
}

namespace {

StopReason failure_reason(core::NewtonStatus s) {
  return s == core::NewtonStatus::evaluation_failed ? StopReason::evaluation_failed
                                                    : StopReason::step_floor;
}

// What the loop carries from one step to the next (BifurcationKit's ContState), in the units of
// its point x (the unit scale unless they follow the point).
struct ArclengthState {
  core::Vector x, tangent;  // the last point and its unit tangent
  core::Vector previous;    // the point before x (secant and quadratic predictors; else empty)
  core::Matrix J;           // the Jacobian at the last point evaluated
  double ds = 0;            // the next step
  // Chord corrections (options.chord_corrections): the base's Jacobian at x, which the next
  // correction starts from (in the units of x), and where (the problem's unknowns) it was
  // computed; empty when the next correction does not try it. The same point's Jacobian, not
  // a new one: ScaledProblem keeps the base's Jacobian per point.
  core::Matrix nearby_base;
  core::Vector nearby_at;
  // Corrections since the last whose chord steps on the nearby Jacobian helped: after two
  // misses the chord is tried only every eighth point. Measured on the contact bar's mode 1
  // below E = 5e-3: the tangent predictor's residual is 2e-2 to 0.5 and a chord step on J(x_k)
  // does not reduce it even at ds = 0.02 (the contact structure moves the Jacobian), so each
  // try costs a factorization and a residual for nothing; at high energy it pays.
  int chord_misses = 0;
  // Units that follow the point (scaled_problem.hpp, LocalScale): after each point the units
  // are those of that point, factor = local_factor_at(x). The first point (or a resumed one)
  // is recorded in the unit scale; every saved state is in the unit scale (z, tangent and
  // previous multiplied by the factor they were computed with), and the next step's vectors
  // are derived from it by the same operations in a resumed run, so a restart continues bit
  // for bit. The branch-point detector keeps its samples in the unit scale (branch_points.hpp).
  core::Vector factor;
};

// The predictor of one step: the direction it leaves x in, and the curvature it adds (empty:
// none).
struct Prediction {
  core::Vector direction;
  core::Vector bend;
};

// The loop proper, in the scaled unknowns z of `problem` (in_scaled_unknowns: the identity view
// when options.scale_unknowns is false). Points are stored in z; the caller converts them. It
// starts from guess (corrected on the hyperplane through it orthogonal to the hint) or, with
// `from`, continues from a saved state (restart.hpp) without correcting or re-deriving anything.
// Its state between steps is an ArclengthState; a step (step()) is predict, correct, accept or
// end, record with the state after it (whose ds is the step-size update), and advance.
class ArclengthLoop {
 public:
  ArclengthLoop(ScaledProblem& problem, const BranchStart& start, core::Corrector& corrector,
                const ContinuationOptions& options, const ContinuationHooks& hooks);
  Branch run(const core::Vector& guess, const core::Vector& hint, const LoopState* from,
             bool record_from);

 private:
  // The first point, from a saved state or from the guess; a Branch when the loop ends there.
  std::optional<Branch> begin_from_state(const LoopState& from, bool record_from);
  std::optional<Branch> begin_from_guess(const core::Vector& guess, const core::Vector& hint_in);
  // One step from x; a Branch when the loop ends.
  std::optional<Branch> step();
  Prediction predict() const;
  // The predicted point at step ds.
  core::Vector predicted_at(const Prediction& p, double ds) const;
  // When a bound lies within the step (LoopSteps::bound_within): the point on it, corrected
  // from the prediction at the distance to it, ends the branch (true). A step that crossed the
  // bound instead costs its own correction and then the landing's.
  bool land_ahead(const Prediction& p);
  // The bordered Jacobian at x on the nearby base Jacobian (empty: none to start from).
  core::Matrix chord_matrix() const;
  CorrectedStep correct(const Prediction& p, const core::Matrix& bordered_nearby, core::Vector& y);
  // Why y turns too far from the predictor direction (empty: it does not).
  std::string turn_rejection(const core::Vector& y, const core::Vector& direction) const;
  // J and the unit tangent at the accepted y (oriented along direction).
  core::EvalStatus tangent_at(const core::Vector& y, const core::Vector& direction,
                              core::Vector& next_tangent);
  // The state the next step starts from (saved with the point for a restart), its ds adapted
  // to the correction's cost.
  std::shared_ptr<LoopState> state_after(const core::Vector& y, const core::Vector& next_tangent,
                                         const CorrectedStep& corrected) const;
  // x, tangent, previous and ds from y and the state after it.
  void advance(const core::Vector& y, const core::Vector& next_tangent, const LoopState& state);
  // Hands the point z (J: s_.J) to the branch-point detector and adds what it located.
  void detect(int index, const core::Vector& z, const core::Vector& tangent, double arclength);

  // Keeps the base's Jacobian at `at` (a copy right after J was computed there) when the next
  // correction tries the chord.
  void keep_base(core::Vector at);
  core::Vector in_unit_scale(const core::Vector& v) const {
    return follow_scale_ && v.size() > 0 ? core::Vector(v.cwiseProduct(s_.factor)) : v;
  }
  // x, tangent and previous from a state in the unit scale, in the units of its point.
  void adopt_units_of(const LoopState& state);

  ScaledProblem& problem_;
  const BranchStart start_;
  core::Corrector& corrector_;
  const ContinuationOptions& options_;
  const double threshold_;  // options.rank.relative_threshold
  // Passing an attached family: a correction that turns away from the predictor direction by
  // more than max_turn_degrees landed on another family (or jumped a fold); it is refused, and
  // ds shrinks, so the branch keeps the direction closest to the incoming one.
  const double max_turn_;
  const bool follow_scale_;  // problem.has_local_scale()
  LoopSteps steps_;
  std::optional<BranchPointDetector> detector_;
  ArclengthState s_;
  // One bordered system for every correction: F plus the arclength row, moved at each step.
  std::optional<core::BorderedSystem> system_;
};

ArclengthLoop::ArclengthLoop(ScaledProblem& problem, const BranchStart& start,
                             core::Corrector& corrector, const ContinuationOptions& options,
                             const ContinuationHooks& hooks)
    : problem_(problem),
      start_(start),
      corrector_(corrector),
      options_(options),
      threshold_(options.rank.relative_threshold),
      max_turn_(options.branch_points.max_turn_degrees),
      follow_scale_(problem.has_local_scale()),
      steps_(problem, corrector, options, hooks, start) {
  if (options.branch_points.detect) {
    detector_.emplace(problem, options, hooks, corrector);
    steps_.add_pending_branch_points([this](int* settled) { return detector_->finish(settled); });
  }
  s_.ds = options.ds;
  s_.factor = core::Vector::Ones(problem.num_unknowns());
}

Branch ArclengthLoop::run(const core::Vector& guess, const core::Vector& hint,
                          const LoopState* from, bool record_from) {
  if (std::optional<Branch> ended =
          from ? begin_from_state(*from, record_from) : begin_from_guess(guess, hint))
    return std::move(*ended);
  system_.emplace(problem_, std::vector<core::BorderRow>{
                                core::BorderRow::linear(s_.tangent, s_.x, 0.0, "arclength")});
  while (steps_.begin_step())
    if (std::optional<Branch> ended = step()) return std::move(*ended);
  return steps_.take();
}

void ArclengthLoop::keep_base(core::Vector at) {
  s_.nearby_at.resize(0);
  s_.nearby_base.resize(0, 0);
  const bool tried = options_.chord_corrections && at.size() > 0 &&
                     (s_.chord_misses < 2 || s_.chord_misses % 8 == 0);
  if (!tried) return;
  if (problem_.base_jacobian(at, s_.nearby_base) == core::EvalStatus::ok)
    s_.nearby_at = std::move(at);
  else
    s_.nearby_base.resize(0, 0);
}

void ArclengthLoop::adopt_units_of(const LoopState& state) {
  s_.x = state.z;
  s_.tangent = state.tangent;
  s_.previous = state.previous;
  if (!follow_scale_) return;
  const core::Vector at = state.z.cwiseProduct(problem_.unit_scale());
  s_.factor = problem_.local_factor_at(at);
  // A first point whose verification waits for the next point is verified now, in the units it
  // was recorded in, when they change (a guess that Newton moved: begin_from_guess).
  if ((problem_.unit_scale().cwiseProduct(s_.factor).array() != problem_.scale().array()).any())
    steps_.verify_first_now();
  problem_.set_factor(s_.factor, problem_.local_residual_factor_at(at));
  s_.x = state.z.cwiseQuotient(s_.factor);
  s_.tangent = state.tangent.cwiseQuotient(s_.factor).normalized();
  if (s_.previous.size() > 0) s_.previous = state.previous.cwiseQuotient(s_.factor);
}

std::optional<Branch> ArclengthLoop::begin_from_state(const LoopState& from, bool record_from) {
  steps_.resume(from, record_from);
  adopt_units_of(from);
  // Units that follow the point set its residual's scale after it was recorded: its residual
  // norm then would not be the one recorded, so the next point verifies without it.
  if (!record_from && !follow_scale_) steps_.remember_saved_point(s_.x);
  s_.ds = from.ds;
  s_.chord_misses = from.chord_misses;
  keep_base(from.jacobian_point);
  if (!detector_) return std::nullopt;
  // The detector is restored as it was before the saved point was added, then the point is
  // added again from its Jacobian (the same bits: the same z). That locates again what adding
  // it had located in the earlier run: the candidates bracketed by the saved samples (at most
  // the last two) and the point, so with after_point >= index - samples. Those rows of the
  // earlier run are replaced by these, the ones before stand (an interrupted run may have
  // stopped before writing them).
  detector_->restore(from.samples, from.jacobian_scale, std::max(from.brackets, 0));
  steps_.branch_points_from(from.index -
                            static_cast<int>(std::min<std::size_t>(from.samples.size(), 2)));
  if (problem_.jacobian(s_.x, s_.J) != core::EvalStatus::ok)
    return steps_.end(StopReason::evaluation_failed,
                      fmt::format("the Jacobian could not be evaluated at the saved point {} ({})",
                                  from.index, steps_.describe(s_.x)));
  detect(from.index, s_.x, s_.tangent, from.arclength);
  return std::nullopt;
}

std::optional<Branch> ArclengthLoop::begin_from_guess(const core::Vector& guess,
                                                      const core::Vector& hint_in) {
  // The first point is the guess corrected on the hyperplane through it orthogonal to the hint.
  core::Vector hint = hint_in.normalized();
  s_.x = guess;
  // In the guess's own units when they follow the point and are not the unit scale there: a
  // guess far above the unit (a saved point corrected again to continue a finished branch)
  // cannot be corrected to the loop's tolerance in the unit scale, whose residual round-off
  // grows with the amplitude (measured: mode 1 of the contact bar at 200 intervals, E = 1e-2,
  // stalls at |F| = 4e-10 against the tolerance 1e-10; its points converge in their own units,
  // where F is divided by ~100).
  if (follow_scale_) {
    const core::Vector at = problem_.to_unknowns(guess);
    const core::Vector f = problem_.local_factor_at(at);
    if ((f.array() != 1.0).any()) {
      s_.factor = f;
      problem_.set_factor(s_.factor, problem_.local_residual_factor_at(at));
      s_.x = guess.cwiseQuotient(s_.factor);
      hint = hint.cwiseQuotient(s_.factor).normalized();
    }
  }
  core::BorderedSystem first(problem_, {core::BorderRow::linear(hint, s_.x, 0.0, "arclength")});
  if (options_.max_points > 1) steps_.verify_first_by_next();
  if (!steps_.start(first, s_.x, "")) return steps_.take();
  if (problem_.jacobian(s_.x, s_.J) != core::EvalStatus::ok ||
      tangent_from_jacobian(s_.J, hint, threshold_, s_.tangent) != core::EvalStatus::ok) {
    steps_.report_first(nullptr);
    return steps_.end(StopReason::evaluation_failed,
                      fmt::format("the Jacobian could not be evaluated at point {} ({})",
                                  start_.index, steps_.describe(s_.x)));
  }
  if (options_.start_along_direction) s_.tangent = hint;
  keep_base(problem_.to_unknowns(s_.x));
  auto state = std::make_shared<LoopState>();
  state->method = Method::arclength;
  state->z = in_unit_scale(s_.x);
  state->tangent = in_unit_scale(s_.tangent);
  state->ds = s_.ds;
  state->jacobian_point = s_.nearby_at;
  if (detector_) state->brackets = detector_->brackets();
  const std::shared_ptr<const LoopState> first_state = state;
  steps_.report_first(std::move(state));
  detect(start_.index, s_.x, s_.tangent, start_.arclength);
  adopt_units_of(*first_state);
  return std::nullopt;
}

std::optional<Branch> ArclengthLoop::step() {
  const int index = steps_.next_index();
  const Prediction p = predict();
  if (land_ahead(p)) return steps_.take();
  system_->set_anchor(0, s_.x);
  system_->set_direction(0, p.direction);
  const core::Matrix bordered_nearby = chord_matrix();
  core::Vector y;
  const CorrectedStep corrected = correct(p, bordered_nearby, y);
  s_.ds = corrected.ds;
  if (!corrected.accepted)
    return steps_.end(
        failure_reason(corrected.last_failure),
        fmt::format("no point {} could be corrected with ds >= ds_min = {:.3g} from {} (last "
                    "Newton status {}: {})",
                    index, options_.ds_min, steps_.describe(s_.x),
                    core::to_string(corrected.last_failure), corrected.last_message));
  const int iterations = corrected.summary.iterations;
  s_.chord_misses =
      bordered_nearby.size() > 0 && corrected.summary.chord_steps > 0 ? 0 : s_.chord_misses + 1;
  core::Vector next_tangent;
  const core::EvalStatus tangent_status = tangent_at(y, p.direction, next_tangent);
  const bool ok = tangent_status == core::EvalStatus::ok;
  const bool last = index + 1 == options_.max_points || !ok;
  const std::shared_ptr<LoopState> state = ok ? state_after(y, next_tangent, corrected) : nullptr;
  if (!steps_.record(s_.x, y, p.direction, iterations, s_.ds, last, state,
                     ok ? &next_tangent : nullptr))
    return steps_.take();
  if (!ok)
    return steps_.end(StopReason::evaluation_failed,
                      fmt::format("the Jacobian could not be evaluated at point {} ({}: {})", index,
                                  core::to_string(tangent_status), steps_.describe(y)));
  detect(index, y, next_tangent, steps_.arclength());
  advance(y, next_tangent, *state);
  return std::nullopt;
}

bool ArclengthLoop::land_ahead(const Prediction& p) {
  double value = 0, ds_to_bound = 0;
  const Bound* bound = steps_.bound_within(s_.ds, value, ds_to_bound);
  if (!bound) return false;
  return steps_.land_ahead(*bound, value, s_.x, predicted_at(p, ds_to_bound), p.direction,
                           ds_to_bound);
}

core::Vector ArclengthLoop::predicted_at(const Prediction& p, double ds) const {
  core::Vector predicted = s_.x + ds * p.direction;
  if (p.bend.size() > 0 && 0.5 * ds * p.bend.norm() <= 0.25) predicted += 0.5 * ds * ds * p.bend;
  return predicted;
}

Prediction ArclengthLoop::predict() const {
  const core::Vector& x = s_.x;
  const core::Vector& tangent = s_.tangent;
  const core::Vector& previous = s_.previous;
  // Predictor direction: the secant through the last two points, or the tangent.
  Prediction p;
  p.direction = tangent;
  if (options_.predictor == Predictor::secant && previous.size() > 0) {
    core::Vector secant = x - previous;
    if (secant.norm() > 0) p.direction = secant.normalized();
  }
  // Quadratic: the chord from the previous point p to x is s t - (s^2 / 2) k + O(s^3) for the
  // curvature vector k (orthogonal to t), so k ~ 2 (s t - (x - p)) / s^2, and the predictor
  // x + ds t + (ds^2 / 2) k lands O(ds^3) from the curve instead of O(ds^2). Only while the
  // bend it adds is below a quarter of the step (else the curve turns too fast for the
  // estimate to hold, as at a branch point) and below 30 degrees between the chord and t.
  if (options_.predictor == Predictor::quadratic && previous.size() == x.size()) {
    const core::Vector chord = x - previous;
    const double s = chord.norm();
    if (s > 0 && chord.dot(tangent) > std::cos(std::numbers::pi / 6) * s) {
      p.bend = 2 * (s * tangent - chord) / (s * s);
      p.bend -= tangent * tangent.dot(p.bend);
    }
  }
  return p;
}

core::Matrix ArclengthLoop::chord_matrix() const {
  core::Matrix bordered_nearby;
  if (s_.nearby_base.size() > 0 &&
      system_->jacobian_with_base(s_.x, problem_.in_current_units(s_.nearby_base),
                                  bordered_nearby) != core::EvalStatus::ok)
    bordered_nearby.resize(0, 0);
  return bordered_nearby;
}

CorrectedStep ArclengthLoop::correct(const Prediction& p, const core::Matrix& bordered_nearby,
                                     core::Vector& y) {
  return steps_.correct(
      s_.ds, y,
      [&](double ds_try, core::Vector& predicted) {
        predicted = predicted_at(p, ds_try);
        system_->set_value(0, ds_try);
        return bordered_nearby.size() > 0 ? corrector_.solve(*system_, predicted, bordered_nearby)
                                          : corrector_.solve(*system_, predicted);
      },
      [&](const core::Vector& corrected_point) {
        return turn_rejection(corrected_point, p.direction);
      });
}

std::string ArclengthLoop::turn_rejection(const core::Vector& y,
                                          const core::Vector& direction) const {
  if (max_turn_ <= 0) return std::string();
  const core::Vector secant = y - s_.x;
  const double norm = secant.norm();
  if (!(norm > 0)) return std::string();
  const double turn =
      std::acos(std::clamp(secant.dot(direction) / norm, -1.0, 1.0)) * 180 / std::numbers::pi;
  if (turn <= max_turn_) return std::string();
  return fmt::format(
      "the step turned by {:.1f} degrees from the predictor direction (max_turn_degrees {:g})",
      turn, max_turn_);
}

core::EvalStatus ArclengthLoop::tangent_at(const core::Vector& y, const core::Vector& direction,
                                           core::Vector& next_tangent) {
  core::EvalStatus status = problem_.jacobian(y, s_.J);
  keep_base(status == core::EvalStatus::ok ? problem_.to_unknowns(y) : core::Vector());
  if (status == core::EvalStatus::ok)
    status = tangent_from_jacobian(s_.J, direction, threshold_, next_tangent);
  // A tangent that turns from the accepted chord x -> y by more than max_turn_degrees
  // contradicts the step just accepted (its secant passed the same check): it is the
  // finite-difference Jacobian's, not the curve's. Measured on the contact bar's mode 1 at
  // 1.3e5 g0: forward differences across a kink of the contact map (7e-5 relative in four
  // columns, against a smallest kept singular value of 7e-6) turn it by 52.8 degrees, and
  // every retry turns as much. The chord keeps the incoming direction, as passing a branch
  // point does. Only in units that follow the point: in a family of more dimensions (a
  // followed branch, follow.hpp) the projected tangent may turn from the chord by design.
  if (follow_scale_ && status == core::EvalStatus::ok && max_turn_ > 0) {
    const core::Vector chord = y - s_.x;
    const double norm = chord.norm();
    if (norm > 0 &&
        std::acos(std::clamp(next_tangent.dot(chord) / norm, -1.0, 1.0)) * 180 / std::numbers::pi >
            max_turn_)
      next_tangent = chord / norm;
  }
  return status;
}

std::shared_ptr<LoopState> ArclengthLoop::state_after(const core::Vector& y,
                                                      const core::Vector& next_tangent,
                                                      const CorrectedStep& corrected) const {
  auto state = std::make_shared<LoopState>();
  state->method = Method::arclength;
  state->z = in_unit_scale(y);
  state->tangent = in_unit_scale(next_tangent);
  if (options_.predictor != Predictor::tangent) state->previous = in_unit_scale(s_.x);
  state->jacobian_point = s_.nearby_at;
  state->chord_misses = s_.chord_misses;
  state->ds = adapted_step(s_.ds, corrected.summary.equivalent_iterations(), options_);
  if (detector_) {
    state->samples = detector_->samples();
    state->jacobian_scale = detector_->jacobian_scale();
    state->brackets = detector_->brackets();
  }
  return state;
}

void ArclengthLoop::advance(const core::Vector& y, const core::Vector& next_tangent,
                            const LoopState& state) {
  s_.ds = state.ds;
  if (follow_scale_) {
    adopt_units_of(state);
    return;
  }
  if (options_.predictor != Predictor::tangent) s_.previous = s_.x;
  s_.x = y;
  s_.tangent = next_tangent;
}

void ArclengthLoop::detect(int index, const core::Vector& z, const core::Vector& tangent,
                           double arclength) {
  if (!detector_) return;
  detector_->add(index, z, tangent, s_.J, arclength);
  int settled = 0;
  for (BranchPointReport& report : detector_->take(&settled))
    steps_.add_branch_point(std::move(report));
  steps_.brackets_settled(settled);
}

Branch arclength_loop(ScaledProblem& problem, const core::Vector& guess, const core::Vector& hint,
                      const LoopState* from, bool record_from, const BranchStart& start,
                      core::Corrector& corrector, const ContinuationOptions& options,
                      const ContinuationHooks& hooks) {
  ArclengthLoop loop(problem, start, corrector, options, hooks);
  return loop.run(guess, hint, from, record_from);
}

}  // namespace

Branch pseudo_arclength(const core::Problem& problem, const core::Vector& guess,
                        const core::Vector& direction, core::Corrector& corrector,
                        const ContinuationOptions& options, const ContinuationHooks& hooks,
                        const BranchStart& start) {
  options.validate();
  check_sizes(problem, guess, direction, "pseudo-arclength follows curves");
  const int n = problem.num_unknowns();
  const core::Vector hint = direction.size() ? direction : core::Vector::Unit(n, n - 1);
  if (!(hint.norm() > 0) || !hint.allFinite())
    throw core::InputError("direction", "must be a finite non-zero vector");

  return in_scaled_unknowns(
      problem, options, hooks, [&](ScaledProblem& scaled, const ContinuationHooks& inner) {
        return arclength_loop(scaled, scaled.to_scaled(guess), scaled.to_scaled(hint), nullptr,
                              false, start, corrector, options, inner);
      });
}

Branch pseudo_arclength(const core::Problem& problem, const LoopState& from, bool record_from,
                        core::Corrector& corrector, const ContinuationOptions& options,
                        const ContinuationHooks& hooks) {
  options.validate();
  check_sizes(problem, from.z, from.tangent, "pseudo-arclength follows curves");
  if (const std::string why = state_mismatch(from, problem, options, Method::arclength);
      !why.empty())
    throw core::InputError("state", why);
  return in_scaled_unknowns(problem, options, hooks,
                            [&](ScaledProblem& scaled, const ContinuationHooks& inner) {
                              return arclength_loop(scaled, from.z, from.tangent, &from,
                                                    record_from, {}, corrector, options, inner);
                            });
}

}  // namespace backbone::continuation
