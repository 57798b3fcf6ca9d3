#include "core/eigen_newton.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <chrono>
#include <cmath>
#include <limits>

namespace backbone::core {

namespace {
// A complete orthogonal decomposition (pivoted QR, then QR of R^T's leading rows) gives the
// Moore-Penrose minimum-norm least-squares solution at a fraction of an SVD's cost; its rank
// cut-off is relative to the largest pivot |R_11|, which is within a factor sqrt(n) of
// sigma_max (Golub & Van Loan 5.4.1), the same scale the SVD cut-off used.
void factorize(const Matrix& J, double rank_cutoff,
               Eigen::CompleteOrthogonalDecomposition<Matrix>& cod) {
  cod.setThreshold(rank_cutoff > 0 ? rank_cutoff : std::numeric_limits<double>::epsilon());
  cod.compute(J);
}

int solve_factorized(const Eigen::CompleteOrthogonalDecomposition<Matrix>& cod, const Vector& rhs,
                     Vector& dx) {
  const Eigen::Index rank = cod.rank();
  if (rank == 0) {
    dx = Vector::Zero(cod.cols());
    return 0;
  }
  dx = cod.solve(rhs);
  return static_cast<int>(rank);
}
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
}  // namespace

int minimum_norm_solve(const Matrix& J, const Vector& rhs, double rank_cutoff, Vector& dx) {
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod;
  factorize(J, rank_cutoff, cod);
  return solve_factorized(cod, rhs, dx);
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

  if (x.size() != problem.num_unknowns())
    return finish(NewtonStatus::evaluation_failed,
                  fmt::format("eigen: starting point has {} entries, problem has {} unknowns",
                              x.size(), problem.num_unknowns()));

  Vector r;
  EvalStatus eval = problem.residual(x, r);
  if (eval != EvalStatus::ok)
    return finish(NewtonStatus::evaluation_failed,
                  fmt::format("eigen: residual at the starting point: {}", to_string(eval)));
  summary.residual_history.push_back(r.lpNorm<Eigen::Infinity>());
  if (summary.residual_history.back() <= options_.residual_tolerance)
    return finish(NewtonStatus::converged,
                  fmt::format("eigen: starting point already converged, ||F||_inf = {:.3e}",
                              summary.residual_history.back()));

  const Vector scale = problem.typical_scale().cwiseAbs();
  Matrix J;
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod;
  // cod holds the factorization of a Jacobian of this solve, or of the nearby one; chord steps
  // on a nearby Jacobian are tried until the first fresh one, later ones only with
  // reuse_jacobian.
  bool have_factorization = false;
  bool chord = options_.reuse_jacobian;
  if (nearby_jacobian && nearby_jacobian->rows() == r.size() &&
      nearby_jacobian->cols() == x.size() && nearby_jacobian->allFinite()) {
    factorize(*nearby_jacobian, options_.rank_cutoff, cod);
    have_factorization = true;
    chord = true;
  }
  Vector dx, trial_x, trial_r;
  constexpr double armijo = 1e-4;
  constexpr int max_halvings = 30;

  for (int iteration = 1; iteration <= options_.max_iterations; ++iteration) {
    summary.iterations = iteration;
    const double norm2 = r.norm();
    // Chord step: the factorization of an earlier Jacobian, kept while it contracts.
    if (have_factorization && chord) {
      const int rank = solve_factorized(cod, -r, dx);
      trial_x = x + dx;
      if (rank > 0 && dx.allFinite() && problem.residual(trial_x, trial_r) == EvalStatus::ok &&
          chord_step_pays(norm2, trial_r, options_)) {
        double scaled_step = 0;
        for (Eigen::Index j = 0; j < x.size(); ++j)
          scaled_step =
              std::max(scaled_step, std::abs(dx[j]) / std::max({std::abs(x[j]), scale[j], 1e-300}));
        x.swap(trial_x);
        r.swap(trial_r);
        ++summary.chord_steps;
        summary.residual_history.push_back(r.lpNorm<Eigen::Infinity>());
        if (summary.residual_history.back() <= options_.residual_tolerance)
          return finish(
              NewtonStatus::converged,
              fmt::format("eigen: converged in {} iterations ({} chord), ||F||_inf "
                          "= {:.3e}",
                          iteration, summary.chord_steps, summary.residual_history.back()));
        if (scaled_step <= options_.step_tolerance)
          return finish(NewtonStatus::stalled,
                        fmt::format("eigen: scaled step {:.3e} below step_tolerance at iteration "
                                    "{}, ||F||_inf = {:.3e}",
                                    scaled_step, iteration, summary.residual_history.back()));
        continue;
      }
      // Too slow (or not evaluable): a fresh Jacobian at x, in this same iteration.
    }
    eval = problem.jacobian(x, J);
    if (eval != EvalStatus::ok)
      return finish(NewtonStatus::evaluation_failed,
                    fmt::format("eigen: Jacobian at iteration {}: {}", iteration, to_string(eval)));
    factorize(J, options_.rank_cutoff, cod);
    have_factorization = true;
    chord = options_.reuse_jacobian;
    const int rank = solve_factorized(cod, -r, dx);
    if (!dx.allFinite())
      return finish(NewtonStatus::linear_solver_failed,
                    fmt::format("eigen: non-finite Newton step at iteration {}", iteration));

    double alpha = 1.0;
    bool accepted = false;
    EvalStatus last_failure = EvalStatus::ok;
    for (int halving = 0; halving <= (options_.line_search ? max_halvings : 0); ++halving) {
      trial_x = x + alpha * dx;
      const EvalStatus s = problem.residual(trial_x, trial_r);
      if (s == EvalStatus::ok &&
          (!options_.line_search || trial_r.norm() <= (1.0 - armijo * alpha) * norm2)) {
        accepted = true;
        break;
      }
      if (s != EvalStatus::ok) last_failure = s;
      if (!options_.line_search && s != EvalStatus::ok)
        return finish(NewtonStatus::evaluation_failed,
                      fmt::format("eigen: residual at iteration {}: {}", iteration, to_string(s)));
      alpha *= 0.5;
    }
    // Scaled step length: relative to max(|x_j|, typical scale_j).
    double scaled_step = 0;
    for (Eigen::Index j = 0; j < x.size(); ++j)
      scaled_step = std::max(
          scaled_step, std::abs(alpha * dx[j]) / std::max({std::abs(x[j]), scale[j], 1e-300}));
    if (!accepted) {
      if (scaled_step <= options_.step_tolerance || rank == 0)
        return finish(NewtonStatus::stalled,
                      fmt::format("eigen: stalled at iteration {} (rank {}), ||F||_inf = {:.3e}",
                                  iteration, rank, summary.residual_history.back()));
      if (last_failure != EvalStatus::ok)
        return finish(NewtonStatus::evaluation_failed,
                      fmt::format("eigen: line search found no evaluable point at iteration "
                                  "{} ({})",
                                  iteration, to_string(last_failure)));
      return finish(NewtonStatus::diverged,
                    fmt::format("eigen: line search failed at iteration {}, ||F||_inf = {:.3e}",
                                iteration, summary.residual_history.back()));
    }
    x.swap(trial_x);
    r.swap(trial_r);
    summary.residual_history.push_back(r.lpNorm<Eigen::Infinity>());
    if (summary.residual_history.back() <= options_.residual_tolerance)
      return finish(NewtonStatus::converged,
                    fmt::format("eigen: converged in {} iterations, ||F||_inf = {:.3e}", iteration,
                                summary.residual_history.back()));
    if (scaled_step <= options_.step_tolerance)
      return finish(NewtonStatus::stalled,
                    fmt::format("eigen: scaled step {:.3e} below step_tolerance at iteration "
                                "{}, ||F||_inf = {:.3e}",
                                scaled_step, iteration, summary.residual_history.back()));
  }
  return finish(NewtonStatus::max_iterations,
                fmt::format("eigen: no convergence in {} iterations, ||F||_inf = {:.3e}",
                            options_.max_iterations, summary.residual_history.back()));
}

}  // namespace backbone::core
