#include "continuation/point_recorder.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"
#include "core/rank_report.hpp"

namespace backbone::continuation {

PointRecorder::PointRecorder(const core::Problem& problem, const ContinuationOptions& options,
                             const core::Problem* counted)
    : problem_(problem), counted_(counted ? *counted : problem), options_(options) {
  if (options.rank_check_every > 0 && options.verify) {
    core::NewtonOptions newton;
    newton.residual_tolerance =
        std::min(newton.residual_tolerance, 0.1 * options.verification.residual_tolerance);
    newton.max_iterations = 60;  // degenerate residuals converge linearly
    verifier_ = core::make_corrector("eigen", newton);
  }
}

void PointRecorder::begin() {
  start_ = std::chrono::steady_clock::now();
  residuals_at_start_ = counted_.counters().residuals;
  jacobians_at_start_ = counted_.counters().jacobians;
}

double PointRecorder::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void PointRecorder::check_rank(BranchPoint& point) {
  core::Matrix J;
  if (problem_.jacobian(point.x, J) != core::EvalStatus::ok) return;
  core::RankReport report = core::rank_report(J, options_.rank);
  if (verifier_) {
    core::verify_null_directions(problem_, point.x, *verifier_, options_.verification, report);
    point.dimension = report.verified_dimension;
  } else {
    point.dimension = report.nullity;
  }
  point.rank = std::move(report);
}

BranchPoint PointRecorder::finish(const core::Vector& x, int index, int newton_iterations,
                                  double ds, double arclength, bool force_rank) {
  BranchPoint p;
  p.index = index;
  p.x = x;
  p.observables = problem_.observables(x);
  core::Vector r;
  p.residual = problem_.residual(x, r) == core::EvalStatus::ok
                   ? r.lpNorm<Eigen::Infinity>()
                   : std::numeric_limits<double>::quiet_NaN();
  p.newton_iterations = newton_iterations;
  p.step_size = ds;
  p.arclength = arclength;
  const bool due = options_.rank_check_every > 0 && index % options_.rank_check_every == 0;
  if (due || (force_rank && options_.rank_check_every > 0)) check_rank(p);
  p.residual_evaluations = counted_.counters().residuals - residuals_at_start_;
  p.jacobian_evaluations = counted_.counters().jacobians - jacobians_at_start_;
  p.seconds = elapsed_seconds();
  return p;
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

bool cancelled(const ContinuationHooks& hooks, Branch& branch) {
  if (!hooks.cancel_requested || !hooks.cancel_requested()) return false;
  branch.reason = StopReason::cancelled;
  branch.message = fmt::format("cancelled after {} points", branch.points.size());
  return true;
}

Branch reached_max_points(Branch branch) {
  branch.reason = StopReason::max_points;
  branch.message = fmt::format("{} points computed", branch.points.size());
  return branch;
}

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

}  // namespace backbone::continuation
