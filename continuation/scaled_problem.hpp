// A problem seen in scaled unknowns z = w .* x ./ s: G(z) = F(s ./ w .* z), with
// s = base.typical_scale() (its units) and w = base.step_weights() (its quadrature weights).
//
// Pseudo-arclength measures steps with a Euclidean norm, which is only meaningful when the
// unknowns have comparable magnitudes. A contact bar with a 1e-5 m gap and a 1e-4 s period, or
// a Duffing orbit whose period is 2 pi while its amplitude is 0.01, is not: unscaled, ds is in
// metres plus seconds and every new scene needs hand-tuned steps. Continuing G instead makes
// ds, ds_min, ds_max and the arclength dimensionless (in units of the typical scale), the
// tangent a scaled direction and the rank report a report on the column-scaled Jacobian
// J diag(s ./ w), whose singular values no longer depend on the units. The weights make |dz| a
// norm of the field the unknowns sample rather than of the node values (the contact bar: the
// L2 norm of u0 over the bar, so a branch has as many points at N = 640 as at N = 40). The
// residual itself is the base's. Both continuation loops run on this view (loop_steps.hpp:
// in_scaled_unknowns), so natural and pseudo-arclength branches report step sizes and
// arclength in the same units. The view keeps the last Jacobian it computed: the loops ask for
// it twice at every point (tangent, then rank report), and the second request at the same z
// (bit for bit) is a copy, not a new finite-difference Jacobian of the base.
//
// Units that follow the point (LocalScale): a problem whose natural unit of some unknowns
// changes along a branch says so by implementing LocalScale. The contact bar's displacements
// are in units of the gap near grazing, but far above it the gap no longer matters (only
// E / g0^2 does) and the orbit's own amplitude is the unit: with a fixed unit a step uniform in
// z cannot cover 1e-6..1e4 J, and the period column of J diag(s), which grows with the
// amplitude, pushes every other singular value below a relative threshold. set_factor(f)
// makes the unit s ./ w .* f (f from local_factor_at(x)); pseudo-arclength re-anchors it at
// every point (continuation/README.md, section 'Scaled unknowns'). unit_scale() stays s ./ w.
//
//   ScaledProblem scaled(problem);                 // s = typical_scale(), w = step_weights()
//   core::Vector z = scaled.to_scaled(x);          // x ./ scale(), scale() = s ./ w
//   scaled.residual(z, r);                         // = problem.residual(x, r)
//   core::Vector back = scaled.to_unknowns(z);     // scale() .* z
//   scaled.set_factor(scaled.local_factor_at(x));  // units of the point x (LocalScale), then
//   z = scaled.to_scaled(x);                       // z in them
#pragma once

#include <mutex>
#include <string>

#include "core/problem.hpp"

namespace backbone::continuation {

// Optional interface of a problem whose natural unit of some unknowns depends on the point:
// entry j of the factor (finite, >= 1) multiplies typical_scale()_j at x; 1 everywhere means
// the fixed units. Equations measured in those units say so with a residual factor (entry i
// divides F_i; empty: none), so that F and the rows that border it keep their balance and a
// residual tolerance stays relative to the point's own size (its round-off grows with it).
class LocalScale {
 public:
  virtual ~LocalScale() = default;
  // false: this instance keeps fixed units (ScaledProblem then ignores the interface).
  virtual bool local_scale_enabled() const { return true; }
  virtual core::Vector local_scale_factor(const core::Vector& x) const = 0;
  virtual core::Vector local_residual_factor(const core::Vector& x) const { return {}; }
};

class ScaledProblem : public core::Problem {
 public:
  // Throws core::InputError when the base's typical scale or step weights are not finite and
  // positive.
  explicit ScaledProblem(const core::Problem& base);
  // Same with an explicit unit scale in place of typical_scale() (ones: unscaled runs, whose
  // norm is then the base's weighted Euclidean norm of the raw unknowns). The step weights are
  // the base's in both cases.
  ScaledProblem(const core::Problem& base, core::Vector scale);
  // The same view (unit scale, current units) of another base with the same unknowns: a
  // clone() of like's base, evaluated on another thread (branch_points.hpp).
  ScaledProblem(const core::Problem& base, const ScaledProblem& like);
  int num_unknowns() const override { return base_.num_unknowns(); }
  int num_equations() const override { return base_.num_equations(); }
  std::string name() const override { return base_.name(); }
  std::string jacobian_description() const override { return base_.jacobian_description(); }
  bool jacobian_exact() const override { return base_.jacobian_exact(); }
  core::Observables observables(const core::Vector& z) const override {
    return base_.observables(to_unknowns(z));
  }
  core::Vector typical_scale() const override { return core::Vector::Ones(num_unknowns()); }
  // z is already weighted: its norm is the plain Euclidean one.
  core::Vector step_weights() const override { return core::Vector::Ones(num_unknowns()); }

  core::Vector to_scaled(const core::Vector& x) const { return x.cwiseQuotient(scale_); }
  core::Vector to_unknowns(const core::Vector& z) const { return z.cwiseProduct(scale_); }
  // x = scale() .* z: s ./ w .* factor.
  const core::Vector& scale() const { return scale_; }
  // s ./ w, whatever the factor: the units a saved loop state is written in (restart.hpp).
  const core::Vector& unit_scale() const { return unit_scale_; }
  // The base implements LocalScale and enables it.
  bool has_local_scale() const { return local_ != nullptr; }
  // The base's factor at x (problem's unknowns); ones without LocalScale. InputError when an
  // entry is not finite and >= 1.
  core::Vector local_factor_at(const core::Vector& x) const;
  // The same for the equations (empty without LocalScale or a residual factor).
  core::Vector local_residual_factor_at(const core::Vector& x) const;
  // Units s ./ w .* factor from now on, F divided by residual_factor (empty: as the base's).
  void set_factor(const core::Vector& factor, const core::Vector& residual_factor = {});
  // The units another view of the same unknowns had (its scale() and residual_factor()), bit for
  // bit: work handed to another thread sees the units of the moment it was handed over.
  void set_units(const core::Vector& scale, const core::Vector& residual_factor);
  // The residual factor set last (empty: none), e.g. to convert a Jacobian back to the unit
  // scale: J_unit = diag(residual_factor) J_z diag(1 ./ factor).
  const core::Vector& residual_factor() const { return residual_factor_; }
  // The base's Jacobian J_x at its unknowns x (not z), a copy when x is the last point asked
  // for in any units, and J_x in the units set now: diag(1 ./ residual factor) J_x diag(scale()),
  // what jacobian(z) returns. A point's Jacobian carried into the next point's units (the
  // nearby Jacobian of its chord correction, continuation/README.md 'Chord corrections') is
  // thus the same bits in an uninterrupted and in a resumed run.
  core::EvalStatus base_jacobian(const core::Vector& x, core::Matrix& J_x) const;
  core::Matrix in_current_units(const core::Matrix& J_x) const;
  const core::Problem& base() const { return base_; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& z, core::Vector& r) const override;
  // J_z = diag(1 ./ residual factor) J_x diag(scale()): the base's Jacobian (analytic or FD with
  // its own step rule), or the last one when z is the last z asked for.
  core::EvalStatus compute_jacobian(const core::Vector& z, core::Matrix& J) const override;

 private:
  const core::Problem& base_;
  const LocalScale* local_ = nullptr;  // the base, when it implements LocalScale
  core::Vector unit_scale_;
  core::Vector scale_;
  core::Vector residual_factor_;    // empty: F as the base's
  mutable std::mutex cache_mutex_;  // compute_jacobian may be called from several threads
  mutable core::Vector cached_x_;   // the base's unknowns; empty: nothing cached
  mutable core::Matrix cached_base_jacobian_;
  mutable double cached_check_tolerance_ = 0;  // core::CorrectorJacobians in force then
};

}  // namespace backbone::continuation
