#include "continuation/internal/loop_steps.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/solvers/bordered_system.hpp"

namespace backbone::continuation {

std::string describe_point(const core::Vector& x) {
  std::string s = "x = (";
  for (Eigen::Index i = 0; i < x.size() && i < 4; ++i)
    s += fmt::format("{}{:.10g}", i ? ", " : "", x[i]);
  if (x.size() > 4) s += fmt::format(", ... {} entries", x.size());
  return s + ")";
}

void check_sizes(const core::Problem& problem, const core::Vector& guess,
                 const core::Vector& direction, const char* what) {
  const int n = problem.num_unknowns();
  const int m = problem.num_equations();
  if (m < n - 1)
    throw core::InputError("method", fmt::format("{}: it needs at least n - 1 equations for n "
                                                 "unknowns ({} unknowns vs {} equations)",
                                                 what, n, m));
  if (guess.size() != n)
    throw core::InputError("guess", fmt::format("dimensions of the guess and the unknowns do not "
                                                "match ({} vs {})",
                                                guess.size(), n));
  if (direction.size() != 0 && direction.size() != n)
    throw core::InputError("direction",
                           fmt::format("dimensions of the direction and the unknowns do not match "
                                       "({} vs {})",
                                       direction.size(), n));
  if (!guess.allFinite()) throw core::InputError("guess", "contains NaN or Inf");
}

LoopSteps::LoopSteps(const ScaledProblem& problem, core::Corrector& corrector,
                     const ContinuationOptions& options, const ContinuationHooks& hooks,
                     const BranchStart& start)
    : problem_(problem),
      corrector_(corrector),
      options_(options),
      hooks_(hooks),
      recorder_(problem, options, &problem.base()),
      first_index_(start.index),
      arclength_(start.arclength),
      switch_index_(start.switch_index),
      rejected_(start.rejected_corrections) {}

std::string LoopSteps::describe(const core::Vector& z) const {
  return describe_point(problem_.to_unknowns(z));
}

std::string LoopSteps::rejection_of(const core::Vector& z) const {
  return hooks_.reject_point ? hooks_.reject_point(z) : std::string();
}

void LoopSteps::attach(BranchPoint& point, std::shared_ptr<LoopState> state) const {
  if (!state) return;
  state->index = point.index;
  state->arclength = point.arclength;
  state->scale = problem_.unit_scale();
  state->switch_index = switch_index_;
  state->rejected_corrections = rejected_;
  point.state = std::move(state);
}

void LoopSteps::report_first(std::shared_ptr<LoopState> state) {
  BranchPoint& first = branch_.points.back();
  if (first_pending_) {
    if (state) first_direction_ = state->tangent;
    attach(first, std::move(state));
    return;
  }
  if (state && state->tangent.size() > 0) recorder_.recheck_dimension(first, state->tangent);
  attach(first, std::move(state));
  if (hooks_.on_point) hooks_.on_point(first);
}

void LoopSteps::flush_first(const core::Vector* neighbour) {
  if (!first_pending_) return;
  first_pending_ = false;
  BranchPoint& first = branch_.points[first_position_];
  recorder_.verify_deferred(first, first_direction_, neighbour);
  if (hooks_.on_point) hooks_.on_point(first);
}

void LoopSteps::resume(const LoopState& state, bool record) {
  const std::string mismatch = state.z.size() != problem_.num_unknowns()
                                   ? std::string("another number of unknowns")
                                   : (state.scale != problem_.unit_scale() ? "another scale" : "");
  if (!mismatch.empty())
    throw core::InputError(
        "state", fmt::format("the saved loop state of point {} has {}", state.index, mismatch));
  first_index_ = state.index;
  arclength_ = state.arclength;
  switch_index_ = state.switch_index;
  rejected_ = state.rejected_corrections;
  known_points_ = state.known_points;
  if (!record) {
    ++first_index_;
    return;
  }
  recorder_.begin();
  const core::Vector direction =
      state.tangent.size() > 0
          ? state.tangent
          : (state.previous.size() > 0 ? core::Vector(state.z - state.previous) : core::Vector());
  BranchPoint point =
      recorder_.finish(state.z, state.index, 0, 0.0, state.arclength, true, direction,
                       state.previous.size() > 0 ? &state.previous : nullptr);
  point.state = std::make_shared<LoopState>(state);
  push(std::move(point));
}

void LoopSteps::push_back(BranchPoint point) {
  branch_.points.push_back(std::move(point));
  point_scales_.push_back(problem_.scale());
}

void LoopSteps::push(BranchPoint point) {
  push_back(std::move(point));
  if (hooks_.on_point) hooks_.on_point(branch_.points.back());
}

Branch LoopSteps::take() {
  flush_first(nullptr);
  if (pending_branch_points_) {
    int settled = 0;
    for (BranchPointReport& report : pending_branch_points_(&settled))
      add_branch_point(std::move(report));
    brackets_settled(settled);
    pending_branch_points_ = nullptr;
  }
  for (std::size_t i = 0; i < branch_.points.size(); ++i)
    branch_.points[i].x = branch_.points[i].x.cwiseProduct(point_scales_[i]);
  point_scales_.clear();
  branch_.rejected_corrections = rejected_;
  return std::move(branch_);
}

void LoopSteps::brackets_settled(int settled) {
  if (settled == brackets_settled_) return;
  brackets_settled_ = settled;
  if (hooks_.on_brackets_settled) hooks_.on_brackets_settled(settled);
}

void LoopSteps::add_branch_point(BranchPointReport report) {
  branch_.branch_points.push_back(std::move(report));
  if (hooks_.on_branch_point) hooks_.on_branch_point(branch_.branch_points.back());
}

Branch LoopSteps::end(StopReason reason, std::string message) {
  branch_.reason = reason;
  branch_.message = std::move(message);
  const Boundary& boundary = options_.boundary;
  const bool stalled = reason == StopReason::step_floor || reason == StopReason::evaluation_failed;
  if (stalled && !boundary.observable.empty() && !branch_.points.empty()) {
    const double value = branch_.points.back().observable(boundary.observable);
    if (value <= boundary.within) {
      branch_.reason = StopReason::boundary_reached;
      branch_.message =
          fmt::format("{} = {:.3g} at point {}: the boundary of the solution set ({})",
                      boundary.observable, value, branch_.points.back().index, branch_.message);
    }
  }
  return take();
}

bool LoopSteps::start(const core::Problem& system, core::Vector& z, const std::string& where) {
  recorder_.begin();
  const core::Vector guess = z;
  const core::NewtonSummary s = corrector_.solve(system, z);
  const std::string rejection = s.converged() ? rejection_of(z) : std::string();
  if (!rejection.empty()) ++rejected_;
  if (hooks_.on_attempt)
    hooks_.on_attempt({0, 0.0, s.converged() && rejection.empty(), s, rejection});
  if (!s.converged()) {
    branch_.reason = s.status == core::NewtonStatus::evaluation_failed
                         ? StopReason::evaluation_failed
                         : StopReason::newton_failed;
    branch_.message = fmt::format("the starting guess did not converge{} ({}; {}): {}", where,
                                  core::to_string(s.status), describe(guess), s.message);
    return false;
  }
  if (!rejection.empty()) {
    branch_.reason = StopReason::newton_failed;
    branch_.message =
        fmt::format("the starting guess converged{} to a point the check rejects ({}): {}", where,
                    describe(z), rejection);
    return false;
  }
  recorder_.defer_verification(defer_first_);
  push_back(recorder_.finish(z, first_index_, s.iterations, 0.0, arclength_, true));
  recorder_.defer_verification(false);
  first_pending_ = defer_first_ && branch_.points.back().rank.has_value();
  first_position_ = branch_.points.size() - 1;
  return true;
}

bool LoopSteps::begin_step() {
  if (next_index() >= options_.max_points) {
    branch_.reason = StopReason::max_points;
    branch_.message = fmt::format("{} points computed", next_index());
    return false;
  }
  if (hooks_.cancel_requested && hooks_.cancel_requested()) {
    branch_.reason = StopReason::cancelled;
    branch_.message = fmt::format("cancelled after {} points", next_index());
    return false;
  }
  recorder_.begin();
  return true;
}

bool LoopSteps::record(const core::Vector& x, const core::Vector& y, const core::Vector& forward,
                       int newton_iterations, double ds, bool force_rank,
                       std::shared_ptr<LoopState> state, const core::Vector* curve_direction) {
  const double arclength_at_x = arclength_;
  arclength_ += (y - x).norm();
  // The curve's direction at y for a dimension re-check: the tangent when the loop has it.
  const core::Vector direction =
      curve_direction
          ? *curve_direction
          : (state && state->tangent.size() == y.size() ? state->tangent : core::Vector(y - x));
  BranchPoint point = recorder_.finish(y, next_index(), newton_iterations, ds, arclength_,
                                       force_rank, direction, &x);
  double bound_value = 0;
  if (const Bound* bound = recorder_.violated_bound(point, bound_value)) {
    land_on_bound(*bound, bound_value, x, y, forward, ds, arclength_at_x);
    return false;
  }
  flush_first(&y);
  attach(point, std::move(state));
  push(std::move(point));
  return true;
}

void LoopSteps::land_on_bound(const Bound& bound, double value, const core::Vector& x,
                              const core::Vector& y, const core::Vector& forward, double ds,
                              double arclength_at_x) {
  const int index = next_index();
  branch_.reason = StopReason::bound_reached;
  branch_.message =
      fmt::format("{} reached its bound {:.6g} after point {}", bound.observable, value, index - 1);
  if (!options_.land_on_bounds) return;
  // x on the bound already (the last point of a branch that landed, taken up again by a
  // restart): the branch ends there, where landing again added a copy of it.
  const core::Observables at_x = problem_.observables(x);
  const auto observed = std::find_if(at_x.begin(), at_x.end(),
                                     [&](const auto& o) { return o.first == bound.observable; });
  if (observed != at_x.end() &&
      std::abs(observed->second - value) <= 1e-9 * std::max(std::abs(value), 1e-300)) {
    branch_.message = fmt::format("{} reached its bound {:.6g} (point {} lies on it)",
                                  bound.observable, value, index - 1);
    return;
  }
  // From the crossing point first, then from the last point inside the bound.
  land(bound, value, {&y, &x}, x, forward, ds, arclength_at_x);
}

bool LoopSteps::land(const Bound& bound, double value,
                     std::initializer_list<const core::Vector*> starts, const core::Vector& x,
                     const core::Vector& forward, double ds, double arclength_at_x) {
  const int index = next_index();
  recorder_.begin();
  const core::BorderedSystem on_bound(problem_,
                                      {core::BorderRow::observable(bound.observable, value)});
  core::Vector z;
  core::NewtonSummary s;
  std::string rejection;
  bool landed = false;
  for (const core::Vector* start : starts) {
    z = *start;
    s = corrector_.solve(on_bound, z);
    const bool ahead = s.converged() && (z - x).dot(forward) > 0;
    rejection = ahead ? rejection_of(z) : std::string();
    landed = ahead && rejection.empty();
    if (!rejection.empty()) ++rejected_;
    if (hooks_.on_attempt) hooks_.on_attempt({index, ds, landed, s, rejection});
    if (s.converged()) break;
  }
  if (!landed) return false;
  const double chord = (z - x).norm();
  BranchPoint landed_point = recorder_.finish(z, index, s.iterations, chord, arclength_at_x + chord,
                                              true, core::Vector(z - x), &x);
  flush_first(&z);
  push(std::move(landed_point));
  branch_.reason = StopReason::bound_reached;
  branch_.message = fmt::format("{} reached its bound {:.6g} (point {} lies on it)",
                                bound.observable, value, index);
  return true;
}

const Bound* LoopSteps::bound_within(double ds, double& value, double& ds_to_bound) const {
  if (!options_.land_on_bounds) return nullptr;
  // The last two points, newest first: the recorded ones, then those known before a resume.
  struct Seen {
    int index;
    double arclength;
    const core::Observables* observables;
  };
  Seen last[2];
  int seen = 0;
  for (auto p = branch_.points.rbegin(); p != branch_.points.rend() && seen < 2; ++p)
    last[seen++] = {p->index, p->arclength, &p->observables};
  for (auto p = known_points_.rbegin(); p != known_points_.rend() && seen < 2; ++p)
    if (seen == 0 || p->index < last[seen - 1].index)
      last[seen++] = {p->index, p->arclength, &p->observables};
  if (seen < 2) return nullptr;
  const Seen &a = last[1], &b = last[0];
  const double chord = b.arclength - a.arclength;
  if (!(chord > 0) || b.index != a.index + 1) return nullptr;
  for (const Bound& bound : options_.bounds) {
    const double va = core::observable_value(*a.observables, bound.observable),
                 vb = core::observable_value(*b.observables, bound.observable);
    if (!std::isfinite(va) || !std::isfinite(vb)) continue;
    const double slope = (vb - va) / chord;
    const double target = slope > 0 ? bound.max : bound.min;
    if (!std::isfinite(target) || slope == 0) continue;
    const double to_bound = (target - vb) / slope;
    if (to_bound > 0 && to_bound <= ds) {
      value = target;
      ds_to_bound = to_bound;
      return &bound;
    }
  }
  return nullptr;
}

}  // namespace backbone::continuation
