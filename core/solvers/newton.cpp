#include "core/solvers/newton.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "core/errors.hpp"
#include "core/solvers/eigen_newton.hpp"
#include "core/solvers/kinsol_newton.hpp"

namespace backbone::core {

const char* to_string(NewtonStatus s) {
  switch (s) {
    case NewtonStatus::converged:
      return "converged";
    case NewtonStatus::stalled:
      return "stalled";
    case NewtonStatus::max_iterations:
      return "max_iterations";
    case NewtonStatus::diverged:
      return "diverged";
    case NewtonStatus::evaluation_failed:
      return "evaluation_failed";
    case NewtonStatus::linear_solver_failed:
      return "linear_solver_failed";
  }
  return "?";
}

void NewtonOptions::validate() const {
  // !(x > 0) rather than x <= 0 so that NaN is rejected too.
  if (!(residual_tolerance > 0) || !std::isfinite(residual_tolerance))
    throw InputError("newton.residual_tolerance",
                     fmt::format("must be finite and > 0 (got {})", residual_tolerance));
  if (!(step_tolerance >= 0) || !std::isfinite(step_tolerance))
    throw InputError("newton.step_tolerance",
                     fmt::format("must be finite and >= 0 (got {})", step_tolerance));
  if (max_iterations < 1)
    throw InputError("newton.max_iterations", fmt::format("must be >= 1 (got {})", max_iterations));
  if (!(rank_cutoff >= 0 && rank_cutoff < 1))
    throw InputError("newton.rank_cutoff", fmt::format("must be in [0, 1) (got {})", rank_cutoff));
  if (!(jacobian_check_tolerance >= 0 && jacobian_check_tolerance < 1))
    throw InputError("newton.jacobian_check_tolerance",
                     fmt::format("must be in [0, 1) (got {})", jacobian_check_tolerance));
  if (!(reuse_contraction > 0 && reuse_contraction < 1))
    throw InputError("newton.reuse_contraction",
                     fmt::format("must be in (0, 1) (got {})", reuse_contraction));
}

std::unique_ptr<Corrector> make_corrector(const std::string& name, const NewtonOptions& options) {
  if (name == "eigen") return std::make_unique<EigenNewton>(options);
  if (name == "kinsol") return std::make_unique<KinsolNewton>(options);
  throw InputError("newton",
                   fmt::format("unknown corrector '{}' (expected eigen or kinsol)", name));
}

namespace {
double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

SummaryRecorder::SummaryRecorder(const Problem& problem)
    : problem_(problem),
      residuals_before_(problem.counters().residuals),
      jacobians_before_(problem.counters().jacobians),
      start_seconds_(now_seconds()) {}

NewtonSummary SummaryRecorder::finish(NewtonSummary& summary, NewtonStatus status,
                                      std::string message) const {
  summary.status = status;
  summary.message = std::move(message);
  summary.residual_evaluations = problem_.counters().residuals - residuals_before_;
  summary.jacobian_evaluations = problem_.counters().jacobians - jacobians_before_;
  summary.seconds = now_seconds() - start_seconds_;
  return summary;
}

}  // namespace backbone::core
