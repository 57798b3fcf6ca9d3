// F plus k rows: the bordered system [F(x); g_1(x); ...; g_k(x)], itself a core::Problem.
//
// Every constrained solve of the toolkit is this one system with different rows: a
// pseudo-arclength step (F plus t . (x - x_k) - ds), a natural-parameter step (F plus
// p(x) - lambda), landing on a bound (F plus energy(x) - E_max), a probe of the rank verification
// (F plus the hyperplane through the stepped point) and a chart of a k-dimensional manifold (F plus
// k tangent-space rows, or an energy row and k - 1 tangent rows; see core/README.md). Being a
// Problem (LOCA's habit), any corrector solves it, KINSOL included when it is square. Rows are
// mutable, so a loop builds the system once and moves its rows from step to step. Observables and
// typical_scale are the base problem's; the system holds a reference to the base.
//
// Each row is one of
//   linear      a . (x - anchor) - value          hyperplane, arclength, fixed unknown (a = e_i)
//   observable  (obs(x) - value) / s, s = |value| (1 when value is 0): a named observable of the
//               base, scaled so that an energy of 1e-3 does not weigh 1e-3 against residual rows of
//               order one in a least-squares solve; Jacobian row by central differences.
//
//   BorderedSystem chart(sphere, {BorderRow::hyperplane(t1, x0), BorderRow::hyperplane(t2, x0)});
//   chart.set_anchor(0, x0 + 0.1 * t1);              // move the first hyperplane along t1
//   Vector x = x0 + 0.1 * t1;
//   corrector.solve(chart, x);                       // an isolated point: 3 equations, 3 unknowns
//   BorderedSystem on_bound(problem, {BorderRow::observable("energy", 1e-3)});
//   on_bound.set_value(0, 2e-3);
#pragma once

#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/types.hpp"

namespace backbone::core {

struct BorderRow {
  enum class Kind { linear, observable };
  Kind kind = Kind::linear;
  Vector direction;             // linear: a (num_unknowns entries)
  Vector anchor;                // linear: the point the row measures from (num_unknowns entries)
  std::string observable_name;  // observable: name of the base's observable
  double value = 0;
  std::string label;  // for BorderedSystem::name(), e.g. "arclength", "energy fixed"

  // a . (x - anchor) - value.
  static BorderRow linear(Vector direction, Vector anchor, double value, std::string label);
  // normal . (x - through) = 0.
  static BorderRow hyperplane(Vector normal, Vector through);
  // x[index] - value (a = e_index, anchor 0) in a problem with num_unknowns unknowns.
  static BorderRow fixed_unknown(int num_unknowns, int index, double value, std::string label);
  // (obs(x) - value) / (|value| or 1).
  static BorderRow observable(std::string name, double value);
};

class BorderedSystem : public Problem {
 public:
  // Throws InputError("bordered_system", ...) when rows is empty, a linear row's direction or
  // anchor does not have num_unknowns finite entries, or an observable row has no name.
  BorderedSystem(const Problem& base, std::vector<BorderRow> rows);

  int num_unknowns() const override { return base_.num_unknowns(); }
  int num_equations() const override { return base_.num_equations() + num_rows(); }
  std::string name() const override;  // "duffing + arclength"
  Observables observables(const Vector& x) const override { return base_.observables(x); }
  Vector typical_scale() const override { return base_.typical_scale(); }

  int num_rows() const { return static_cast<int>(rows_.size()); }
  const BorderRow& row(int i) const;
  const Problem& base() const { return base_; }
  // Mutators; InputError for a row index out of range, a size mismatch, or an anchor/direction
  // set on an observable row.
  void set_value(int i, double value);
  void set_anchor(int i, Vector anchor);
  void set_direction(int i, Vector direction);
  // Divisor of row i: 1 for a linear row, |value| (1 when 0 or not finite) for an observable.
  double row_scale(int i) const;
  // This system's Jacobian at x assembled on a given Jacobian of the base (at x or near it:
  // the nearby Jacobian of a chord correction, newton.hpp), the rows' gradients at x.
  EvalStatus jacobian_with_base(const Vector& x, const Matrix& base_jacobian, Matrix& J) const;

 protected:
  // An observable row that cannot be evaluated (observable not reported, NaN) gives failed.
  EvalStatus compute_residual(const Vector& x, Vector& r) const override;
  // The base's Jacobian (analytic or its own FD), then each row's gradient: a for a linear row,
  // central differences of the observable with step cbrt(eps) * max(|x_j|, typical_scale_j).
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override;

 private:
  const BorderRow& checked(int i, const char* what) const;
  void check_linear(const Vector& v, const char* what) const;

  const Problem& base_;
  std::vector<BorderRow> rows_;
  bool has_observable_rows_ = false;
};

// Value of the observable `name` reported by problem at x; NaN when it is not reported.
double observable_value(const Problem& problem, const std::string& name, const Vector& x);

}  // namespace backbone::core
