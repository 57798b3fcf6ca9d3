// A nonlinear system F(x) = 0 with m equations in n unknowns (m <= n is allowed).
//
// The interface is deliberately tiny (Ceres' CostFunction is the model): sizes and a residual.
// The Jacobian defaults to finite differences (see finite_difference.hpp for the step rule),
// compressed when the problem declares its sparsity (jacobian_pattern, compressed_jacobian.hpp);
// a problem that knows its Jacobian overrides compute_jacobian. Public entry points are
// non-virtual: they count evaluations, time them and check the output for NaN/Inf, so every
// solver reports cost the same way. compute_residual must be safe to call concurrently on a
// const object (finite-difference columns may be evaluated in parallel).
//
//   class Circle : public backbone::core::Problem {
//    public:
//     int num_unknowns() const override { return 2; }
//     int num_equations() const override { return 1; }
//    protected:
//     EvalStatus compute_residual(const Vector& x, Vector& r) const override {
//       r.resize(1); r[0] = x.squaredNorm() - 1.0; return EvalStatus::ok;
//     }
//   };
//   Circle c; Vector r; c.residual(Vector::Ones(2), r);   // r = [1], c.counters().residuals == 1
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/types.hpp"

namespace backbone::core {

// Outcome of one evaluation. Numerical failure is a value, never an exception.
enum class EvalStatus {
  ok,
  non_finite,  // the residual or Jacobian contains NaN or Inf
  failed,      // the problem could not evaluate at x (e.g. a period <= 0, simulation blew up)
};
const char* to_string(EvalStatus s);

// Evaluation counters, safe to update from several threads.
struct EvaluationCounters {
  std::atomic<long> residuals{0};
  std::atomic<long> jacobians{0};
  std::atomic<long> residual_nanoseconds{0};
  std::atomic<long> jacobian_nanoseconds{0};
  // Default (finite-difference) Jacobians computed compressed from a jacobian_pattern, those
  // whose pattern failed its check and were recomputed from its wider pattern, and those
  // recomputed column by column (every pattern tried failed).
  std::atomic<long> compressed_jacobians{0};
  std::atomic<long> jacobian_widenings{0};
  std::atomic<long> jacobian_fallbacks{0};
  void reset();
};

// Which entries of J = dF/dx may be nonzero (core/README.md, section 'Compressed Jacobians'):
// row_columns[i] lists the columns j with J_ij possibly != 0, beside the dense_columns, which
// may be nonzero in every row. Every entry outside is taken as exactly 0 by the compressed
// finite-difference Jacobian (compressed_jacobian.hpp), which verifies that claim at each use.
// A pattern may name a wider one to try when its check fails, before column by column (e.g. a
// pattern exact near the solutions and a structural bound everywhere); it is built only then.
struct JacobianPattern {
  std::vector<std::vector<int>> row_columns;  // num_equations() rows
  std::vector<int> dense_columns;
  // Builds the wider pattern when the check fails (may be empty: none). Called before the
  // Jacobian call that asked for the pattern returns, so it may refer to the problem; a pattern
  // can cost as much to build as a residual (the contact bar's), and the wider one is seldom
  // needed.
  std::function<JacobianPattern()> wider;
  // The check's relative tolerance tau (compressed_jacobian.cpp): entries this pattern drops
  // pass unnoticed up to about tau of their row's size. A narrow pattern with a `wider` one
  // behind it can ask for less than the default 1e-3, so that what it drops is negligible
  // wherever J matters beyond Newton's convergence (rank tests, branch points).
  double check_tolerance = 1e-3;
  // True when the pattern holds every entry F can have, whatever x: its check then fails only
  // where F has a kink between x and the check's step (a contact event that the step moves),
  // which column-by-column differences straddle as well. Inside a corrector's scope
  // (CorrectorJacobians with a tolerance > 0), such a pattern's Jacobian is kept when its check
  // fails (CompressedJacobianReport::kept_unchecked) instead of being recomputed column by column:
  // the corrector's answer is judged by F alone (core/README.md, 'Compressed Jacobians').
  bool structural = false;
};

// A named scalar derived from a solution point (period, energy, frequency...).
using Observables = std::vector<std::pair<std::string, double>>;
// The value of the observable `name` in the list; NaN when it is not there.
double observable_value(const Observables& observables, const std::string& name);

class Problem {
 public:
  Problem() = default;
  virtual ~Problem() = default;

  virtual int num_unknowns() const = 0;
  virtual int num_equations() const = 0;
  virtual std::string name() const { return "problem"; }

  // Residual r = F(x), resized to num_equations(). Counts, times, checks finiteness.
  EvalStatus residual(const Vector& x, Vector& r) const;
  // Jacobian J = dF/dx (num_equations x num_unknowns). Analytic if overridden, else FD.
  EvalStatus jacobian(const Vector& x, Matrix& J) const;

  // Scalars worth reporting at a solution (written as columns of branch.csv). Default: none.
  virtual Observables observables(const Vector& x) const { return {}; }

  // Typical magnitude of each unknown, used by the finite-difference step rule and by
  // scaled norms. Default: ones.
  virtual Vector typical_scale() const { return Vector::Ones(num_unknowns()); }

  // Weights w of the continuation norm, |dx|^2 = sum_j (w_j dx_j / typical_scale_j)^2: how much
  // each unknown counts in a step length, not its unit (so the finite-difference step rule,
  // which uses typical_scale alone, does not see them). A problem whose unknowns sample a field
  // on a grid returns quadrature weights (sqrt(dx / L) for nodal values), so that a step
  // measures the change of the field, not the number of nodes, and a branch has as many
  // points at every resolution. Finite and > 0. Default: ones (the Euclidean norm).
  virtual Vector step_weights() const { return Vector::Ones(num_unknowns()); }

  // Sparsity of the Jacobian at x, used by the default finite-difference Jacobian to perturb
  // structurally independent columns together (one residual per colour instead of one per
  // column). It must be a deterministic function of x alone (no state learnt at earlier
  // points: a resumed run must reproduce an uninterrupted one bit for bit). A wrong pattern
  // costs time, not accuracy: the compressed Jacobian is checked along one direction and
  // recomputed column by column when the check fails (counters().jacobian_fallbacks).
  // Default: none, every column is differenced on its own.
  virtual std::optional<JacobianPattern> jacobian_pattern(const Vector& x) const {
    return std::nullopt;
  }

  // Where compute_jacobian's matrix comes from, for the reports (the trace's header and
  // summary.txt's `jacobian`): "differences" (the default's), or the override's own words.
  virtual std::string jacobian_description() const { return "differences"; }
  // Whether compute_jacobian's matrix is the derivative to round-off (analytic or an exact
  // tangent), not a difference quotient or an integration's: the branch-point location then
  // runs its test function down to round-off (continuation/README.md, 'Branch points').
  virtual bool jacobian_exact() const { return false; }

  const EvaluationCounters& counters() const { return counters_; }
  void reset_counters() const { counters_.reset(); }

  // An independent copy of this problem that another thread may evaluate while this one is
  // evaluated (its own counters and caches), or nullptr, the default. Work that can run beside
  // the caller's (the branch-point location on a second core, continuation/README.md 'Branch
  // points') runs on the caller's thread when there is no copy. A problem whose members are
  // values or shared immutable data implements it as make_unique<Self>(*this).
  virtual std::unique_ptr<Problem> clone() const { return nullptr; }

 protected:
  // A copy counts its own evaluations from zero (clone()).
  Problem(const Problem&) {}
  Problem& operator=(const Problem&) { return *this; }
  virtual EvalStatus compute_residual(const Vector& x, Vector& r) const = 0;
  // Default: forward finite differences, default_jacobian_threads() threads: compressed
  // (compressed_finite_difference_jacobian) when jacobian_pattern(x) gives a pattern, else
  // column by column (finite_difference_jacobian).
  virtual EvalStatus compute_jacobian(const Vector& x, Matrix& J) const;

 private:
  mutable EvaluationCounters counters_;
};

}  // namespace backbone::core
