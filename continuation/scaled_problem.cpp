#include "continuation/scaled_problem.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"

namespace backbone::continuation {

ScaledProblem::ScaledProblem(const core::Problem& base)
    : ScaledProblem(base, base.typical_scale().cwiseAbs()) {}

namespace {
void check_positive(const char* what, const core::Vector& v, int unknowns) {
  if (v.size() != unknowns)
    throw core::InputError(what, fmt::format("has {} entries for {} unknowns", v.size(), unknowns));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]) || !(v[i] > 0))
      throw core::InputError(what,
                             fmt::format("entry {} must be finite and > 0 (got {})", i, v[i]));
}
}  // namespace

ScaledProblem::ScaledProblem(const core::Problem& base, core::Vector scale) : base_(base) {
  check_positive("typical_scale", scale, base.num_unknowns());
  const core::Vector weights = base.step_weights();
  check_positive("step_weights", weights, base.num_unknowns());
  scale_ = scale.cwiseQuotient(weights);
}

core::EvalStatus ScaledProblem::compute_residual(const core::Vector& z, core::Vector& r) const {
  return base_.residual(to_unknowns(z), r);
}

core::EvalStatus ScaledProblem::compute_jacobian(const core::Vector& z, core::Matrix& J) const {
  {
    const std::lock_guard<std::mutex> lock(cache_mutex_);
    // Exact equality: the same point, so the base would return the same matrix.
    if (cached_z_.size() == z.size() && cached_z_ == z) {
      J = cached_jacobian_;
      return core::EvalStatus::ok;
    }
  }
  const core::EvalStatus s = base_.jacobian(to_unknowns(z), J);
  if (s != core::EvalStatus::ok) return s;
  J = J * scale_.asDiagonal();
  const std::lock_guard<std::mutex> lock(cache_mutex_);
  cached_z_ = z;
  cached_jacobian_ = J;
  return s;
}

}  // namespace backbone::continuation
