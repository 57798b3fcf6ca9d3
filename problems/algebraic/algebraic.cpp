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

RepeatedRows::RepeatedRows(int unknowns, int rows, int copies)
    : unknowns_(unknowns), rows_(rows), copies_(copies) {
  if (copies < 1) throw core::InputError("copies", fmt::format("must be >= 1 (got {})", copies));
}

core::EvalStatus RepeatedRows::compute_residual(const core::Vector& x, core::Vector& r) const {
  core::Vector once(rows_);
  rows(x, once);
  for (int c = 0; c < copies_; ++c) r.segment(c * rows_, rows_) = (c + 1.0) * once;
  return core::EvalStatus::ok;
}

core::EvalStatus RepeatedRows::compute_jacobian(const core::Vector& x, core::Matrix& J) const {
  core::Matrix once(rows_, unknowns_);
  rows_jacobian(x, once);
  for (int c = 0; c < copies_; ++c) J.middleRows(c * rows_, rows_) = (c + 1.0) * once;
  return core::EvalStatus::ok;
}

void Transcritical::rows(const core::Vector& x, core::Vector& r) const {
  r[0] = x[0] * (x[1] - 1.0 - x[0]);
}
void Transcritical::rows_jacobian(const core::Vector& x, core::Matrix& J) const {
  J(0, 0) = x[1] - 1.0 - 2.0 * x[0];
  J(0, 1) = x[0];
}

void AxisAndCircle::rows(const core::Vector& x, core::Vector& r) const {
  r[0] = x[0] * (x[0] * x[0] + x[1] * x[1] - 1.0);
}
void AxisAndCircle::rows_jacobian(const core::Vector& x, core::Matrix& J) const {
  J(0, 0) = 3.0 * x[0] * x[0] + x[1] * x[1] - 1.0;
  J(0, 1) = 2.0 * x[0] * x[1];
}

void AxisAndPlane::rows(const core::Vector& x, core::Vector& r) const {
  r[0] = x[0] * (x[2] - 1.0);
  r[1] = x[1] * (x[2] - 1.0);
}
void AxisAndPlane::rows_jacobian(const core::Vector& x, core::Matrix& J) const {
  J.setZero();
  J(0, 0) = x[2] - 1.0;
  J(0, 2) = x[0];
  J(1, 1) = x[2] - 1.0;
  J(1, 2) = x[1];
}

}  // namespace backbone::algebraic
