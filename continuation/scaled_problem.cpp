#include "continuation/scaled_problem.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"

namespace backbone::continuation {

ScaledProblem::ScaledProblem(const core::Problem& base)
    : ScaledProblem(base, base.typical_scale().cwiseAbs()) {}

ScaledProblem::ScaledProblem(const core::Problem& base, core::Vector scale)
    : base_(base), scale_(std::move(scale)) {
  if (scale_.size() != base.num_unknowns())
    throw core::InputError("typical_scale", fmt::format("has {} entries for {} unknowns",
                                                        scale_.size(), base.num_unknowns()));
  for (Eigen::Index i = 0; i < scale_.size(); ++i)
    if (!std::isfinite(scale_[i]) || !(scale_[i] > 0))
      throw core::InputError("typical_scale",
                             fmt::format("entry {} must be finite and > 0 (got {})", i, scale_[i]));
}

core::EvalStatus ScaledProblem::compute_residual(const core::Vector& z, core::Vector& r) const {
  return base_.residual(to_unknowns(z), r);
}

core::EvalStatus ScaledProblem::compute_jacobian(const core::Vector& z, core::Matrix& J) const {
  const core::EvalStatus s = base_.jacobian(to_unknowns(z), J);
  if (s == core::EvalStatus::ok) J = J * scale_.asDiagonal();
  return s;
}

}  // namespace backbone::continuation
