#include "problems/algebraic/algebraic.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"

namespace backbone::algebraic {

core::EvalStatus FoldCurve::compute_residual(const core::Vector& x, core::Vector& r) const {
  r[0] = x[0] * x[0] + x[1] - 1.0;
  return core::EvalStatus::ok;
}

core::EvalStatus FoldCurve::compute_jacobian(const core::Vector& x, core::Matrix& J) const {
  J(0, 0) = 2.0 * x[0];
  J(0, 1) = 1.0;
  return core::EvalStatus::ok;
}

QuadricSurface::QuadricSurface(int ambient_dimension, double radius)
    : ambient_dimension_(ambient_dimension), radius_(radius) {
  if (ambient_dimension < 2)
    throw core::InputError("dimension", fmt::format("must be >= 2 (got {})", ambient_dimension));
  if (!(radius > 0) || !std::isfinite(radius))
    throw core::InputError("radius", fmt::format("must be finite and > 0 (got {})", radius));
}

core::Observables QuadricSurface::observables(const core::Vector& x) const {
  static const char* names[] = {"x", "y", "z"};
  core::Observables o;
  for (int i = 0; i < ambient_dimension_ && i < 3; ++i) o.emplace_back(names[i], x[i]);
  o.emplace_back("angle", std::atan2(x[1], x[0]));
  return o;
}

core::EvalStatus QuadricSurface::compute_residual(const core::Vector& x, core::Vector& r) const {
  r[0] = x.squaredNorm() - radius_ * radius_;
  return core::EvalStatus::ok;
}

core::EvalStatus QuadricSurface::compute_jacobian(const core::Vector& x, core::Matrix& J) const {
  J.row(0) = 2.0 * x.transpose();
  return core::EvalStatus::ok;
}

}  // namespace backbone::algebraic
