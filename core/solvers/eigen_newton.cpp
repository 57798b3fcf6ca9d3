#include "core/solvers/eigen_newton.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "core/jacobians/compressed_jacobian.hpp"
#include "core/solvers/sparse_least_squares.hpp"

namespace backbone::core {

namespace {
// The least-squares factorisation of J (m x n). The Moore-Penrose minimum-norm solution is
// what a rank-deficient J needs; a complete orthogonal decomposition (pivoted QR, then QR of
// R^T's leading rows) gives it at a fraction of an SVD's cost, its rank cut-off relative to the
// largest pivot |R_11|, within a factor sqrt(n) of sigma_max (Golub & Van Loan 5.4.1), the
// scale the SVD cut-off used. Where J has full column rank by a wide margin the minimum-norm
// solution is the plain least-squares one, and a Householder QR without pivoting (blocked,
// 3.4x cheaper than the COD at 321 x 161: core/README.md, 'Newton correctors') gives it. The
// margin is checked on R: two steps of inverse iteration on R^T R from a fixed start estimate
// sigma_min(R) from above (||R^-1 R^-T z|| / ||z|| <= 1 / sigma_min^2), quickly where it
// matters (a sigma_min far below the next is found in one step); QR is kept when that estimate
// is above 1e3 times the cut-off of |R|'s largest diagonal entry, else the COD factorises R
// (J^+ = R^+ Q^T: 2/5 of a COD of J when m = 2n). The two give the same solution up to
// round-off (cond(J) eps).
class LeastSquares {
 public:
  void compute(const Matrix& J, double rank_cutoff, bool damped = false) {
    const double cutoff = rank_cutoff > 0 ? rank_cutoff : std::numeric_limits<double>::epsilon();
    use_sparse_ = sparse_.compute(J, cutoff, damped);
    if (!use_sparse_) dense(J, cutoff);
    cutoff_ = cutoff;
  }
  int rank() const {
    return use_sparse_ ? static_cast<int>(sparse_.cols())
           : use_qr_   ? static_cast<int>(qr_.cols())
                       : static_cast<int>(cod_.rank());
  }
  int cols() const {
    return static_cast<int>(use_sparse_ ? sparse_.cols() : use_qr_ ? qr_.cols() : cod_.cols());
  }
  // Least-squares solution of J dx = rhs (minimum norm for a rank-deficient J). Returns the
  // rank used.
  int solve(const Vector& rhs, Vector& dx) {
    if (use_sparse_) {
      if (sparse_.solve(rhs, dx)) return rank();
      // The iteration did not converge on this right-hand side (not seen on the contact bar):
      // the dense factorisation of the same J from here on.
      use_sparse_ = false;
      dense(sparse_.matrix(), cutoff_);
    }
    const int r = rank();
    if (r == 0) {
      dx = Vector::Zero(cols());
      return 0;
    }
    if (use_qr_) {
      dx = qr_.solve(rhs);
    } else if (on_r_) {
      Vector y = qr_.householderQ().transpose() * rhs;
      dx = cod_.solve(y.head(qr_.cols()));
    } else {
      dx = cod_.solve(rhs);
    }
    return r;
  }

 private:
  bool well_conditioned(double cutoff) const {
    const Eigen::Index n = qr_.cols();
    const auto R = qr_.matrixQR().topRows(n).template triangularView<Eigen::Upper>();
    const double largest = qr_.matrixQR().topRows(n).diagonal().cwiseAbs().maxCoeff();
    if (!(largest > 0) || !std::isfinite(largest)) return false;
    Vector z = Vector::Ones(n);
    double estimate = largest;
    for (int step = 0; step < 2; ++step) {
      const double before = z.norm();
      Vector y = R.transpose().solve(z);
      y = R.solve(y);
      const double grow = y.norm() / before;  // <= 1 / sigma_min^2
      if (!std::isfinite(grow) || !(grow > 0)) return false;
      estimate = std::min(estimate, 1.0 / std::sqrt(grow));
      z = y / y.norm();
    }
    return estimate > 1e3 * cutoff * largest;
  }

  // The dense path: Householder QR where J is well conditioned, else the COD of its R.
  void dense(const Matrix& J, double cutoff) {
    use_qr_ = false;
    on_r_ = false;
    cod_.setThreshold(cutoff);
    if (J.rows() >= J.cols() && J.cols() > 0) {
      qr_.compute(J);
      use_qr_ = well_conditioned(cutoff);
      if (!use_qr_) {
        // J = Q_1 R with orthonormal Q_1, so J^+ = R^+ Q_1^T: the COD of the n x n R gives J's
        // minimum-norm solution, at 2/5 of the COD of the m x n J when m = 2n (its pivots,
        // hence its rank, are R's, the same singular values up to round-off).
        const Eigen::Index n = J.cols();
        cod_.compute(Matrix(qr_.matrixQR().topRows(n).template triangularView<Eigen::Upper>()));
        on_r_ = true;
      }
    }
    if (!use_qr_ && !on_r_) cod_.compute(J);
  }

  SparseLeastSquares sparse_;
  bool use_sparse_ = false;  // solve() may replace it by the dense path of the same J
  double cutoff_ = 0;
  bool use_qr_ = false;
  bool on_r_ = false;  // cod_ factorises qr_'s R, not J
  Eigen::HouseholderQR<Matrix> qr_;
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod_;
};

// A chord step is kept when it cuts ||F||_2 by 1 / reuse_contraction, or, more slowly but still
// by half, when at its rate six more such steps reach the tolerance: a fresh Jacobian costs a
// residual per column (or per colour), a chord step one. Measured on the contact bar's
// verification probes at N = 40: rates 0.03 to 0.07, then 0.14 on the last step above the
// tolerance, which the strict rule paid a whole Jacobian for.
bool chord_step_pays(double norm2, const Vector& trial_r, const NewtonOptions& options) {
  const double rate = trial_r.norm() / norm2;
  if (rate <= options.reuse_contraction) return true;
  return rate <= 0.5 &&
         trial_r.lpNorm<Eigen::Infinity>() * std::pow(rate, 6) <= options.residual_tolerance;
}

// Scaled length of the step alpha dx from x: max_j |alpha dx_j| / max(|x_j|, typical scale_j).
double scaled_step_length(const Vector& dx, double alpha, const Vector& x, const Vector& scale) {
  double scaled_step = 0;
  for (Eigen::Index j = 0; j < x.size(); ++j)
    scaled_step = std::max(scaled_step,
                           std::abs(alpha * dx[j]) / std::max({std::abs(x[j]), scale[j], 1e-300}));
  return scaled_step;
}

// A chord step from x on the kept factorization: taken (x and r moved, its scaled length in
// scaled_step) when it can be evaluated and pays (chord_step_pays); else x and r stay.
bool chord_step(const Problem& problem, LeastSquares& factorization, const NewtonOptions& options,
                const Vector& scale, double norm2, Vector& x, Vector& r, Vector& dx,
                Vector& trial_x, Vector& trial_r, double& scaled_step) {
  const int rank = factorization.solve(-r, dx);
  trial_x = x + dx;
  if (!(rank > 0 && dx.allFinite() && problem.residual(trial_x, trial_r) == EvalStatus::ok &&
        chord_step_pays(norm2, trial_r, options)))
    return false;
  scaled_step = scaled_step_length(dx, 1.0, x, scale);
  x.swap(trial_x);
  r.swap(trial_r);
  return true;
}

// The backtracking line search along dx from x (|F(x)|_2 = norm2): alpha halves until the
// Armijo condition holds (at most 30 times); without options.line_search, the full step only.
struct LineSearch {
  double alpha = 1.0;
  bool accepted = false;                     // trial_x = x + alpha dx, trial_r = F(trial_x)
  EvalStatus last_failure = EvalStatus::ok;  // of the last residual that failed
  bool failed_full_step = false;             // without line search: F(x + dx) failed (last_failure)
};

LineSearch line_search(const Problem& problem, const NewtonOptions& options, const Vector& x,
                       const Vector& dx, double norm2, Vector& trial_x, Vector& trial_r) {
  constexpr double armijo = 1e-4;
  constexpr int max_halvings = 30;
  LineSearch out;
  for (int halving = 0; halving <= (options.line_search ? max_halvings : 0); ++halving) {
    trial_x = x + out.alpha * dx;
    const EvalStatus s = problem.residual(trial_x, trial_r);
    if (s == EvalStatus::ok &&
        (!options.line_search || trial_r.norm() <= (1.0 - armijo * out.alpha) * norm2)) {
      out.accepted = true;
      break;
    }
    if (s != EvalStatus::ok) out.last_failure = s;
    if (!options.line_search && s != EvalStatus::ok) {
      out.failed_full_step = true;
      return out;
    }
    out.alpha *= 0.5;
  }
  return out;
}

// How a solve ends after a step (the history's last entry: ||F||_inf at the new x): converged,
// stalled on a scaled step below step_tolerance, or not yet (nullopt). chord: the step was a
// chord step (the message counts them).
struct StepEnd {
  NewtonStatus status;
  std::string message;
};

std::optional<StepEnd> after_step(const NewtonSummary& summary, const NewtonOptions& options,
                                  double scaled_step, int iteration, bool chord) {
  const double norm = summary.residual_history.back();
  if (norm <= options.residual_tolerance)
    return StepEnd{NewtonStatus::converged,
                   chord ? fmt::format("eigen: converged in {} iterations ({} chord), ||F||_inf "
                                       "= {:.3e}",
                                       iteration, summary.chord_steps, norm)
                         : fmt::format("eigen: converged in {} iterations, ||F||_inf = {:.3e}",
                                       iteration, norm)};
  if (scaled_step <= options.step_tolerance)
    return StepEnd{NewtonStatus::stalled,
                   fmt::format("eigen: scaled step {:.3e} below step_tolerance at iteration "
                               "{}, ||F||_inf = {:.3e}",
                               scaled_step, iteration, norm)};
  return std::nullopt;
}

// The start of a solve: F(x) into r and its norm into the history; an end when x does not fit
// the problem, F(x) fails, or x already converged.
std::optional<StepEnd> start_solve(const Problem& problem, const Vector& x,
                                   const NewtonOptions& options, Vector& r,
                                   NewtonSummary& summary) {
  if (x.size() != problem.num_unknowns())
    return StepEnd{NewtonStatus::evaluation_failed,
                   fmt::format("eigen: starting point has {} entries, problem has {} unknowns",
                               x.size(), problem.num_unknowns())};
  const EvalStatus eval = problem.residual(x, r);
  if (eval != EvalStatus::ok)
    return StepEnd{NewtonStatus::evaluation_failed,
                   fmt::format("eigen: residual at the starting point: {}", to_string(eval))};
  summary.residual_history.push_back(r.lpNorm<Eigen::Infinity>());
  if (summary.residual_history.back() <= options.residual_tolerance)
    return StepEnd{NewtonStatus::converged,
                   fmt::format("eigen: starting point already converged, ||F||_inf = {:.3e}",
                               summary.residual_history.back())};
  return std::nullopt;
}

}  // namespace

int minimum_norm_solve(const Matrix& J, const Vector& rhs, double rank_cutoff, Vector& dx) {
  LeastSquares ls;
  ls.compute(J, rank_cutoff);
  return ls.solve(rhs, dx);
}

EigenNewton::EigenNewton(const NewtonOptions& options) : options_(options) {
  options_.validate();
}

NewtonSummary EigenNewton::solve(const Problem& problem, Vector& x) {
  return solve_from(problem, x, nullptr);
}

NewtonSummary EigenNewton::solve(const Problem& problem, Vector& x, const Matrix& nearby_jacobian) {
  return solve_from(problem, x, &nearby_jacobian);
}

NewtonSummary EigenNewton::solve_from(const Problem& problem, Vector& x,
                                      const Matrix* nearby_jacobian) {
  const SummaryRecorder recorder(problem);
  NewtonSummary summary;
  auto finish = [&](NewtonStatus status, std::string message) {
    return recorder.finish(summary, status, std::move(message));
  };

  Vector r;
  if (const std::optional<StepEnd> end = start_solve(problem, x, options_, r, summary))
    return finish(end->status, end->message);

  const Vector scale = problem.typical_scale().cwiseAbs();
  Matrix J;
  LeastSquares factorization;
  // factorization holds the factorization of a Jacobian of this solve, or of the nearby one; chord
  // steps on a nearby Jacobian are tried until the first fresh one, later ones only with
  // reuse_jacobian.
  bool have_factorization = false;
  bool chord = options_.reuse_jacobian;
  if (nearby_jacobian && nearby_jacobian->rows() == r.size() &&
      nearby_jacobian->cols() == x.size() && nearby_jacobian->allFinite()) {
    factorization.compute(*nearby_jacobian, options_.rank_cutoff, options_.damped_sparse);
    have_factorization = true;
    chord = true;
  }
  Vector dx, trial_x, trial_r;

  for (int iteration = 1; iteration <= options_.max_iterations; ++iteration) {
    summary.iterations = iteration;
    const double norm2 = r.norm();
    // Chord step: the factorization of an earlier Jacobian, kept while it contracts. Too slow
    // (or not evaluable): a fresh Jacobian at x, in this same iteration.
    double scaled_step = 0;
    if (have_factorization && chord &&
        chord_step(problem, factorization, options_, scale, norm2, x, r, dx, trial_x, trial_r,
                   scaled_step)) {
      ++summary.chord_steps;
      summary.residual_history.push_back(r.lpNorm<Eigen::Infinity>());
      if (const std::optional<StepEnd> end =
              after_step(summary, options_, scaled_step, iteration, true))
        return finish(end->status, end->message);
      continue;
    }
    EvalStatus eval;
    {
      const CorrectorJacobians loose(options_.jacobian_check_tolerance);
      eval = problem.jacobian(x, J);
    }
    if (eval != EvalStatus::ok)
      return finish(NewtonStatus::evaluation_failed,
                    fmt::format("eigen: Jacobian at iteration {}: {}", iteration, to_string(eval)));
    factorization.compute(J, options_.rank_cutoff, options_.damped_sparse);
    have_factorization = true;
    chord = options_.reuse_jacobian;
    const int rank = factorization.solve(-r, dx);
    if (!dx.allFinite())
      return finish(NewtonStatus::linear_solver_failed,
                    fmt::format("eigen: non-finite Newton step at iteration {}", iteration));

    const LineSearch search = line_search(problem, options_, x, dx, norm2, trial_x, trial_r);
    if (search.failed_full_step)
      return finish(NewtonStatus::evaluation_failed,
                    fmt::format("eigen: residual at iteration {}: {}", iteration,
                                to_string(search.last_failure)));
    // Scaled step length: relative to max(|x_j|, typical scale_j).
    scaled_step = scaled_step_length(dx, search.alpha, x, scale);
    if (!search.accepted) {
      if (scaled_step <= options_.step_tolerance || rank == 0)
        return finish(NewtonStatus::stalled,
                      fmt::format("eigen: stalled at iteration {} (rank {}), ||F||_inf = {:.3e}",
                                  iteration, rank, summary.residual_history.back()));
      if (search.last_failure != EvalStatus::ok)
        return finish(NewtonStatus::evaluation_failed,
                      fmt::format("eigen: line search found no evaluable point at iteration "
                                  "{} ({})",
                                  iteration, to_string(search.last_failure)));
      return finish(NewtonStatus::diverged,
                    fmt::format("eigen: line search failed at iteration {}, ||F||_inf = {:.3e}",
                                iteration, summary.residual_history.back()));
    }
    x.swap(trial_x);
    r.swap(trial_r);
    summary.residual_history.push_back(r.lpNorm<Eigen::Infinity>());
    if (const std::optional<StepEnd> end =
            after_step(summary, options_, scaled_step, iteration, false))
      return finish(end->status, end->message);
  }
  return finish(NewtonStatus::max_iterations,
                fmt::format("eigen: no convergence in {} iterations, ||F||_inf = {:.3e}",
                            options_.max_iterations, summary.residual_history.back()));
}

}  // namespace backbone::core
