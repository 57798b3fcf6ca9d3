#include "core/solvers/bordered_system.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "core/errors.hpp"

namespace backbone::core {

BorderRow BorderRow::linear(Vector direction, Vector anchor, double value, std::string label) {
  BorderRow row;
  row.kind = Kind::linear;
  row.direction = std::move(direction);
  row.anchor = std::move(anchor);
  row.value = value;
  row.label = std::move(label);
  return row;
}

BorderRow BorderRow::hyperplane(Vector normal, Vector through) {
  return linear(std::move(normal), std::move(through), 0.0, "hyperplane");
}

BorderRow BorderRow::fixed_unknown(int num_unknowns, int index, double value, std::string label) {
  if (index < 0 || index >= num_unknowns)
    throw InputError("bordered_system",
                     fmt::format("unknown index {} out of range [0, {})", index, num_unknowns));
  return linear(Vector::Unit(num_unknowns, index), Vector::Zero(num_unknowns), value,
                std::move(label));
}

BorderRow BorderRow::observable(std::string name, double value) {
  BorderRow row;
  row.kind = Kind::observable;
  row.label = name + " fixed";
  row.observable_name = std::move(name);
  row.value = value;
  return row;
}

double observable_value(const Problem& problem, const std::string& name, const Vector& x) {
  for (const auto& [key, value] : problem.observables(x))
    if (key == name) return value;
  return std::numeric_limits<double>::quiet_NaN();
}

namespace {}  // namespace

BorderedSystem::BorderedSystem(const Problem& base, std::vector<BorderRow> rows)
    : base_(base), rows_(std::move(rows)) {
  if (rows_.empty()) throw InputError("bordered_system", "needs at least one row (got none)");
  for (const BorderRow& row : rows_) {
    if (row.kind == BorderRow::Kind::linear) {
      check_linear(row.direction, "direction");
      check_linear(row.anchor, "anchor");
    } else if (row.observable_name.empty()) {
      throw InputError("bordered_system", "an observable row needs the observable's name");
    } else {
      has_observable_rows_ = true;
    }
  }
}

void BorderedSystem::check_linear(const Vector& v, const char* what) const {
  if (v.size() != base_.num_unknowns())
    throw InputError(
        "bordered_system",
        fmt::format("dimensions of a row's {} and the unknowns do not match ({} vs {})", what,
                    v.size(), base_.num_unknowns()));
  if (!v.allFinite())
    throw InputError("bordered_system", fmt::format("a row's {} contains NaN or Inf", what));
}

std::string BorderedSystem::name() const {
  std::string s = base_.name();
  for (const BorderRow& row : rows_) s += " + " + row.label;
  return s;
}

const BorderRow& BorderedSystem::checked(int i, const char* what) const {
  if (i < 0 || i >= num_rows())
    throw InputError("bordered_system",
                     fmt::format("{}: row {} out of range [0, {})", what, i, num_rows()));
  return rows_[static_cast<std::size_t>(i)];
}

const BorderRow& BorderedSystem::row(int i) const {
  return checked(i, "row");
}

void BorderedSystem::set_value(int i, double value) {
  checked(i, "set_value");
  rows_[static_cast<std::size_t>(i)].value = value;
}

void BorderedSystem::set_anchor(int i, Vector anchor) {
  if (checked(i, "set_anchor").kind != BorderRow::Kind::linear)
    throw InputError("bordered_system", fmt::format("set_anchor: row {} is not linear", i));
  check_linear(anchor, "anchor");
  rows_[static_cast<std::size_t>(i)].anchor = std::move(anchor);
}

void BorderedSystem::set_direction(int i, Vector direction) {
  if (checked(i, "set_direction").kind != BorderRow::Kind::linear)
    throw InputError("bordered_system", fmt::format("set_direction: row {} is not linear", i));
  check_linear(direction, "direction");
  rows_[static_cast<std::size_t>(i)].direction = std::move(direction);
}

double BorderedSystem::row_scale(int i) const {
  const BorderRow& row = checked(i, "row_scale");
  if (row.kind == BorderRow::Kind::linear) return 1.0;
  const double size = std::abs(row.value);
  return size > 0 && std::isfinite(size) ? size : 1.0;
}

EvalStatus BorderedSystem::compute_residual(const Vector& x, Vector& r) const {
  Vector f;
  const EvalStatus s = base_.residual(x, f);
  if (s != EvalStatus::ok) return s;
  const Eigen::Index m = f.size();
  r.resize(m + num_rows());
  r.head(m) = f;
  const Observables observed = has_observable_rows_ ? base_.observables(x) : Observables{};
  for (int i = 0; i < num_rows(); ++i) {
    const BorderRow& row = rows_[static_cast<std::size_t>(i)];
    if (row.kind == BorderRow::Kind::linear) {
      r[m + i] = row.direction.dot(x - row.anchor) - row.value;
    } else {
      r[m + i] = (observable_value(observed, row.observable_name) - row.value) / row_scale(i);
      if (!std::isfinite(r[m + i])) return EvalStatus::failed;
    }
  }
  return EvalStatus::ok;
}

EvalStatus BorderedSystem::compute_jacobian(const Vector& x, Matrix& J) const {
  Matrix base_jacobian;
  const EvalStatus s = base_.jacobian(x, base_jacobian);
  if (s != EvalStatus::ok) return s;
  return jacobian_with_base(x, base_jacobian, J);
}

EvalStatus BorderedSystem::jacobian_with_base(const Vector& x, const Matrix& base_jacobian,
                                              Matrix& J) const {
  if (base_jacobian.rows() != base_.num_equations() || base_jacobian.cols() != num_unknowns() ||
      x.size() != num_unknowns())
    throw InputError("bordered_system",
                     fmt::format("jacobian_with_base: a {} x {} base Jacobian at a point of {} "
                                 "entries, the base has {} equations and {} unknowns",
                                 base_jacobian.rows(), base_jacobian.cols(), x.size(),
                                 base_.num_equations(), num_unknowns()));
  const Eigen::Index m = base_jacobian.rows();
  const Eigen::Index n = base_jacobian.cols();
  J.resize(m + num_rows(), n);
  J.topRows(m) = base_jacobian;
  for (int i = 0; i < num_rows(); ++i) {
    const BorderRow& row = rows_[static_cast<std::size_t>(i)];
    if (row.kind == BorderRow::Kind::linear) J.row(m + i) = row.direction.transpose();
  }
  if (!has_observable_rows_) return EvalStatus::ok;
  // Central differences of the observables (cheap closed forms of x in every problem here):
  // step cbrt(eps) * max(|x_j|, scale_j), one pair of observables() calls per column for all
  // observable rows.
  const Vector scale = base_.typical_scale();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double h = 6e-6 * std::max(std::abs(x[j]), scale[j]);
    Vector xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    const Observables plus = base_.observables(xp), minus = base_.observables(xm);
    for (int i = 0; i < num_rows(); ++i) {
      const BorderRow& row = rows_[static_cast<std::size_t>(i)];
      if (row.kind != BorderRow::Kind::observable) continue;
      J(m + i, j) = (observable_value(plus, row.observable_name) -
                     observable_value(minus, row.observable_name)) /
                    ((xp[j] - xm[j]) * row_scale(i));
    }
  }
  for (int i = 0; i < num_rows(); ++i)
    if (!J.row(m + i).allFinite()) return EvalStatus::non_finite;
  return EvalStatus::ok;
}

}  // namespace backbone::core
