#include "continuation/scaled_problem.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"
#include "core/jacobians/compressed_jacobian.hpp"

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

ScaledProblem::ScaledProblem(const core::Problem& base, core::Vector scale)
    : base_(base), local_(dynamic_cast<const LocalScale*>(&base)) {
  check_positive("typical_scale", scale, base.num_unknowns());
  const core::Vector weights = base.step_weights();
  check_positive("step_weights", weights, base.num_unknowns());
  unit_scale_ = scale.cwiseQuotient(weights);
  scale_ = unit_scale_;
  if (local_ && !local_->local_scale_enabled()) local_ = nullptr;
}

ScaledProblem::ScaledProblem(const core::Problem& base, const ScaledProblem& like)
    : base_(base),
      local_(like.local_ ? dynamic_cast<const LocalScale*>(&base) : nullptr),
      unit_scale_(like.unit_scale_),
      scale_(like.scale_),
      residual_factor_(like.residual_factor_) {
  if (base.num_unknowns() != like.num_unknowns() || base.num_equations() != like.num_equations())
    throw core::InputError("problem", "a view of another base must have the same sizes");
}

void ScaledProblem::set_units(const core::Vector& scale, const core::Vector& residual_factor) {
  check_positive("scale", scale, num_unknowns());
  if (residual_factor.size() > 0)
    check_positive("residual_factor", residual_factor, num_equations());
  scale_ = scale;
  residual_factor_ = residual_factor;
}

core::Vector ScaledProblem::local_factor_at(const core::Vector& x) const {
  if (!local_) return core::Vector::Ones(num_unknowns());
  core::Vector factor = local_->local_scale_factor(x);
  check_positive("local_scale_factor", factor, num_unknowns());
  for (Eigen::Index i = 0; i < factor.size(); ++i)
    if (!(factor[i] >= 1))
      throw core::InputError("local_scale_factor",
                             fmt::format("entry {} must be >= 1 (got {})", i, factor[i]));
  return factor;
}

core::Vector ScaledProblem::local_residual_factor_at(const core::Vector& x) const {
  if (!local_) return {};
  core::Vector factor = local_->local_residual_factor(x);
  if (factor.size() > 0) check_positive("local_residual_factor", factor, num_equations());
  return factor;
}

void ScaledProblem::set_factor(const core::Vector& factor, const core::Vector& residual_factor) {
  check_positive("factor", factor, num_unknowns());
  if (residual_factor.size() > 0)
    check_positive("residual_factor", residual_factor, num_equations());
  scale_ = unit_scale_.cwiseProduct(factor);
  residual_factor_ = residual_factor;
}

core::EvalStatus ScaledProblem::compute_residual(const core::Vector& z, core::Vector& r) const {
  const core::EvalStatus s = base_.residual(to_unknowns(z), r);
  if (s == core::EvalStatus::ok && residual_factor_.size() > 0)
    r = r.cwiseQuotient(residual_factor_);
  return s;
}

core::EvalStatus ScaledProblem::compute_jacobian(const core::Vector& z, core::Matrix& J) const {
  const core::EvalStatus s = base_jacobian(to_unknowns(z), J);
  if (s == core::EvalStatus::ok) J = in_current_units(J);
  return s;
}

core::EvalStatus ScaledProblem::base_jacobian(const core::Vector& x, core::Matrix& J_x) const {
  {
    const std::lock_guard<std::mutex> lock(cache_mutex_);
    // Exact equality: the same point, so the base would return the same matrix (checked to
    // the same tolerance: a corrector's looser Jacobian is not a rank report's).
    if (cached_x_.size() == x.size() && cached_x_ == x &&
        cached_check_tolerance_ == core::CorrectorJacobians::tolerance()) {
      J_x = cached_base_jacobian_;
      return core::EvalStatus::ok;
    }
  }
  const core::EvalStatus s = base_.jacobian(x, J_x);
  if (s != core::EvalStatus::ok) return s;
  const std::lock_guard<std::mutex> lock(cache_mutex_);
  cached_x_ = x;
  cached_base_jacobian_ = J_x;
  cached_check_tolerance_ = core::CorrectorJacobians::tolerance();
  return s;
}

core::Matrix ScaledProblem::in_current_units(const core::Matrix& J_x) const {
  core::Matrix J = J_x * scale_.asDiagonal();
  if (residual_factor_.size() > 0) J = residual_factor_.cwiseInverse().asDiagonal() * J;
  return J;
}

}  // namespace backbone::continuation
