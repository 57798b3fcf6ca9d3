// Newton correctors behind one interface: solve F(x) = 0 from a starting guess, in place.
//
// Two backends: "eigen" (dense Gauss-Newton with Moore-Penrose minimum-norm steps, so it also
// handles under-determined and rank-deficient systems) and "kinsol" (SUNDIALS KINSOL, square
// systems only, dense linear solver and line search). Both fill the same NewtonSummary, so a
// run can be compared across backends. Options are a plain struct with defaults and a
// validate() that names the bad field.
//
//   NewtonOptions opt; opt.residual_tolerance = 1e-12;
//   auto newton = make_corrector("kinsol", opt);      // throws InputError on a bad name
//   Vector x = guess;
//   NewtonSummary s = newton->solve(problem, x);
//   if (!s.converged()) fmt::print("{}\n", s.message);
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/problem.hpp"

namespace backbone::core {

struct NewtonOptions {
  double residual_tolerance = 1e-10;  // stop when ||F||_inf <= this
  double step_tolerance = 1e-14;      // stalled when the scaled step falls below this
  int max_iterations = 25;
  bool line_search = true;  // backtracking on ||F||_2 (KINSOL: KIN_LINESEARCH)
  // Relative singular-value cut-off of the minimum-norm step (eigen backend): singular
  // values below rank_cutoff * sigma_max are treated as zero.
  double rank_cutoff = 1e-12;
  // Eigen backend: after an iteration with a fresh Jacobian, try the next steps with its
  // factorization (chord steps, one residual each) and keep a chord step when it reduces
  // ||F||_2 by at least 1 / reuse_contraction (or by half when six more steps at its rate
  // would reach residual_tolerance); else compute a fresh Jacobian at once.
  bool reuse_jacobian = false;
  double reuse_contraction = 0.1;  // in (0, 1)
  // Eigen backend: the check tolerance of the compressed Jacobians of its iterations, where
  // their pattern asks for less (core::CorrectorJacobians): the answer is judged by F alone, so
  // an entry a pattern drops costs at most a slower contraction. 0: the patterns' own.
  double jacobian_check_tolerance = 1e-2;  // in [0, 1)
  // Eigen backend: a sparse J too ill-conditioned for the exact sparse path (a rank-deficient
  // one) takes a damped step, (J^T J + mu I) dx = -J^T F by the sparse factor
  // (SparseLeastSquares::compute, damped), instead of the dense COD's minimum-norm one: O(nnz)
  // instead of O(m n^2). For the rank verification's probes (core::VerifyOptions), whose
  // bordered systems keep the other null directions of a many-dimensional family.
  bool damped_sparse = false;
  void validate() const;  // throws InputError naming the field, e.g. "newton.max_iterations"
};

enum class NewtonStatus {
  converged,
  stalled,  // step below step_tolerance before the residual was small
  max_iterations,
  diverged,           // residual grew beyond recovery / line search failed
  evaluation_failed,  // residual or Jacobian returned non-ok (NaN, failed simulation)
  linear_solver_failed,
};
const char* to_string(NewtonStatus s);

struct NewtonSummary {
  NewtonStatus status = NewtonStatus::max_iterations;
  int iterations = 0;
  std::vector<double> residual_history;  // ||F||_inf at the start and after each iteration
  long residual_evaluations = 0;
  long jacobian_evaluations = 0;
  // Of `iterations`, those that used an earlier factorization (chord steps, one residual each)
  // instead of a fresh Jacobian.
  int chord_steps = 0;
  double seconds = 0;
  std::string message;  // backend's own words (KINSOL's flag text) plus context
  bool converged() const { return status == NewtonStatus::converged; }
  double final_residual() const {
    return residual_history.empty() ? -1.0 : residual_history.back();
  }
  // The iterations a step-size rule should see: each fresh-Jacobian iteration counts one, and
  // every four chord steps count one. A chord step contracts ||F|| by at least 1 /
  // reuse_contraction (10x by default) where a Newton step near the solution squares it: a
  // correction from 1e-4 to 1e-12 takes 2-3 Newton iterations or 8 chord steps, so a pure
  // chord correction of up to 12 steps still reads as a fast one (continuation/README.md,
  // 'Chord corrections').
  int equivalent_iterations() const { return iterations - chord_steps + (chord_steps + 3) / 4; }
};

class Corrector {
 public:
  virtual ~Corrector() = default;
  virtual std::string name() const = 0;
  // Solves problem(x) = 0 starting from x; x holds the last iterate on return.
  virtual NewtonSummary solve(const Problem& problem, Vector& x) = 0;
  // The same, given a Jacobian of `problem` at a nearby point (a branch's previous point, the
  // point a probe steps from): a backend with chord steps starts with its factorization and
  // computes a fresh Jacobian only once a chord step contracts ||F||_2 by less than
  // 1 / reuse_contraction. The answer is judged by F alone, so a poor nearby Jacobian costs
  // one residual, never accuracy. The default ignores it.
  virtual NewtonSummary solve(const Problem& problem, Vector& x, const Matrix& nearby_jacobian) {
    (void)nearby_jacobian;
    return solve(problem, x);
  }
};

// Bookkeeping shared by every corrector: from construction on, counts the problem's
// evaluations and the wall time, and fills those fields of a summary when the solve ends.
class SummaryRecorder {
 public:
  explicit SummaryRecorder(const Problem& problem);
  NewtonSummary finish(NewtonSummary& summary, NewtonStatus status, std::string message) const;

 private:
  const Problem& problem_;
  long residuals_before_, jacobians_before_;
  double start_seconds_;
};

// name: "eigen" or "kinsol". Throws InputError("newton", ...) for anything else.
std::unique_ptr<Corrector> make_corrector(const std::string& name, const NewtonOptions& options);

}  // namespace backbone::core
