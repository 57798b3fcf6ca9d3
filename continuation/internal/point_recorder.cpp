#include "continuation/internal/point_recorder.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "continuation/scaled_problem.hpp"
#include "core/rank/rank_report.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::continuation {

PointRecorder::PointRecorder(const core::Problem& problem, const ContinuationOptions& options,
                             const core::Problem* counted)
    : problem_(problem), counted_(counted ? *counted : problem), options_(options) {
  if (options.rank_check_every > 0 && options.verify)
    verifier_ = core::make_verifier(options.verification, options.rank);
}

void PointRecorder::begin() {
  start_ = std::chrono::steady_clock::now();
  residuals_at_start_ = counted_.counters().residuals;
  jacobians_at_start_ = counted_.counters().jacobians;
}

double PointRecorder::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void PointRecorder::check_rank(BranchPoint& point, const core::Vector& curve_direction,
                               const core::Vector* previous) {
  core::Matrix J;
  if (problem_.jacobian(point.x, J) != core::EvalStatus::ok) return;
  core::RankOptions rank = options_.rank;
  rank.full_spectrum = false;  // sigma_max and the values around the threshold suffice here
  core::RankReport report = core::rank_report(J, rank);
  const core::Matrix* nearby = options_.chord_corrections ? &J : nullptr;
  if (verifier_ && defer_) {
    point.dimension = report.nullity;
    point.rank = std::move(report);
    return;
  }
  if (verifier_) {
    core::verify_null_directions(problem_, point.x, *verifier_, options_.verification, report,
                                 nearby, previous, known_residual(previous));
    point.dimension = report.verified_dimension;
  } else {
    point.dimension = report.nullity;
  }
  point.rank = std::move(report);
  recheck_dimension(point, curve_direction, nearby, previous);
  recheck_inside(point);
}

void PointRecorder::verify_deferred(BranchPoint& point, const core::Vector& curve_direction,
                                    const core::Vector* neighbour) {
  if (!verifier_ || !point.rank) return;
  core::verify_null_directions(problem_, point.x, *verifier_, options_.verification, *point.rank,
                               nullptr, neighbour, known_residual(neighbour));
  point.dimension = point.rank->verified_dimension;
  recheck_dimension(point, curve_direction, nullptr, neighbour);
  recheck_inside(point);
}

// The loops record points in scaled unknowns whose units may follow the point
// (ScaledProblem::set_factor): the anchor is kept in the base problem's unknowns.
core::Vector PointRecorder::to_unknowns(const core::Vector& x) const {
  const auto* scaled = dynamic_cast<const ScaledProblem*>(&problem_);
  return scaled ? scaled->to_unknowns(x) : x;
}

core::Vector PointRecorder::from_unknowns(const core::Vector& unknowns) const {
  const auto* scaled = dynamic_cast<const ScaledProblem*>(&problem_);
  return scaled ? scaled->to_scaled(unknowns) : unknowns;
}

void PointRecorder::recheck_inside(BranchPoint& point) {
  const Boundary& boundary = options_.boundary;
  if (!verifier_ || !boundary.verify_inside || boundary.observable.empty() || !point.rank ||
      point.dimension < 1)
    return;
  const double at = point.observable(boundary.observable);
  if (!(at <= boundary.within)) return;
  const core::VerifyOptions& verify = options_.verification;
  // The directions to probe: the chord towards the anchor, then the candidates.
  const core::Matrix& D = point.rank->null_directions;
  core::Matrix directions(point.x.size(), D.cols() + 1);
  Eigen::Index count = 0;
  if (anchor_.size() == point.x.size()) {
    const core::Vector chord = from_unknowns(anchor_) - point.x;
    if (chord.norm() > 0) directions.col(count++) = chord.normalized();
  }
  for (Eigen::Index i = 0; i < D.cols(); ++i) directions.col(count++) = D.col(i);
  const core::Vector scale = problem_.typical_scale().cwiseAbs();
  // The neighbour deepest inside: of every direction's verification probes on either side
  // (core::probe_neighbour, `reach` times the verification's step along d, so that the
  // verification's own probes from the neighbour stay inside), the one with the largest
  // observable. A direction along the boundary moves it by round-off, one across it by the step.
  constexpr double reach = 10;
  core::Vector inside;
  double deepest = at;
  for (Eigen::Index i = 0; i < count; ++i) {
    const core::Vector d = directions.col(i);
    const double seen = d.cwiseProduct(scale).norm();
    for (const double side : {1.0, -1.0}) {
      const core::NeighbourProbe p = core::probe_neighbour(
          problem_, point.x, d, side * reach * verify.step * (seen > 0 ? seen : 1.0), *verifier_,
          verify);
      if (!p.found) continue;
      const double value =
          core::observable_value(problem_.observables(p.point), boundary.observable);
      if (value > deepest) {
        deepest = value;
        inside = p.point;
      }
    }
  }
  if (inside.size() == 0) return;
  // J there is the solution set's own.
  core::Matrix J;
  if (problem_.jacobian(inside, J) != core::EvalStatus::ok) return;
  core::RankOptions rank = options_.rank;
  rank.full_spectrum = false;
  core::RankReport there = core::rank_report(J, rank);
  if (there.nullity <= point.dimension) return;
  core::verify_null_directions(problem_, inside, *verifier_, verify, there,
                               options_.chord_corrections ? &J : nullptr, &point.x, point.residual);
  if (there.verified_dimension > point.dimension) {
    point.dimension = there.verified_dimension;
    point.rank = std::move(there);
    point.dimension_flag = DimensionFlag::inside;
  }
}

void PointRecorder::recheck_dimension(BranchPoint& point, const core::Vector& curve_direction,
                                      const core::Matrix* jacobian, const core::Vector* previous) {
  if (!verifier_ || !point.rank || point.rank->verified_dimension < 0 || point.dimension >= 1)
    return;
  point.dimension_flag = DimensionFlag::unconfirmed;
  const double norm = curve_direction.norm();
  if (curve_direction.size() != point.x.size() || !(norm > 0) || !std::isfinite(norm)) return;
  core::RankReport along;
  along.null_directions = curve_direction / norm;
  core::verify_null_directions(problem_, point.x, *verifier_, options_.verification, along,
                               jacobian, previous, known_residual(previous));
  if (along.verified_dimension != 1) return;
  // The curve is there. The rest of the candidate null space, orthogonal to it: the columns of
  // an orthonormal basis of span(D) after the curve direction's component in it.
  point.dimension_flag = DimensionFlag::rechecked;
  point.dimension = 1;
  const core::Matrix& D = point.rank->null_directions;
  const Eigen::Index k = D.cols();
  if (k < 2) return;
  const core::Vector in_span = D.transpose() * along.null_directions.col(0);
  if (!(in_span.norm() > 0)) return;
  Eigen::HouseholderQR<core::Matrix> qr(core::Matrix(in_span / in_span.norm()));
  const core::Matrix Q = qr.householderQ();
  core::RankReport others;
  others.null_directions = D * Q.rightCols(k - 1);
  core::verify_null_directions(problem_, point.x, *verifier_, options_.verification, others,
                               jacobian, previous, known_residual(previous));
  point.dimension += std::max(others.verified_dimension, 0);
}

BranchPoint PointRecorder::finish(const core::Vector& x, int index, int newton_iterations,
                                  double ds, double arclength, bool force_rank,
                                  const core::Vector& curve_direction,
                                  const core::Vector* previous) {
  BranchPoint p;
  p.index = index;
  p.x = x;
  p.observables = problem_.observables(x);
  // The branch's point 0, inside its solution set: the anchor of recheck_inside.
  if (index == 0 && options_.boundary.verify_inside &&
      p.observable(options_.boundary.observable) > options_.boundary.within)
    anchor_ = to_unknowns(x);
  p.residual = residual_norm(x);
  p.newton_iterations = newton_iterations;
  p.step_size = ds;
  p.arclength = arclength;
  // Before the rank report, whose probes evaluate elsewhere: a problem that keeps its last
  // shot (HybridOrbitProblem) then has the monodromy of x at hand.
  add_floquet(p);
  const bool due = options_.rank_check_every > 0 && index % options_.rank_check_every == 0;
  if (due || (force_rank && options_.rank_check_every > 0))
    check_rank(p, curve_direction, previous);
  last_x_ = p.x;
  last_residual_ = p.residual;
  p.residual_evaluations = counted_.counters().residuals - residuals_at_start_;
  p.jacobian_evaluations = counted_.counters().jacobians - jacobians_at_start_;
  p.seconds = elapsed_seconds();
  return p;
}

double PointRecorder::residual_norm(const core::Vector& x) const {
  core::Vector r;
  return problem_.residual(x, r) == core::EvalStatus::ok ? r.lpNorm<Eigen::Infinity>()
                                                         : std::numeric_limits<double>::quiet_NaN();
}

void PointRecorder::remember(const core::Vector& x) {
  last_x_ = x;
  last_residual_ = residual_norm(x);
}

double PointRecorder::known_residual(const core::Vector* x) const {
  if (x && x->size() == last_x_.size() && *x == last_x_) return last_residual_;
  return std::numeric_limits<double>::quiet_NaN();
}

void PointRecorder::add_floquet(BranchPoint& point) const {
  if (!options_.stability) return;
  // The point's unknowns in the base's units (the loops record points in scaled unknowns).
  point.floquet = core::floquet_at(counted_, to_unknowns(point.x), options_.floquet);
}

const Bound* PointRecorder::violated_bound(const BranchPoint& point, double& value) const {
  for (const Bound& b : options_.bounds) {
    const double v = point.observable(b.observable);
    if (std::isnan(v)) continue;
    if (v < b.min) {
      value = b.min;
      return &b;
    }
    if (v > b.max) {
      value = b.max;
      return &b;
    }
  }
  return nullptr;
}

}  // namespace backbone::continuation
