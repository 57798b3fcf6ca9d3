#include <algorithm>
#include <cmath>
#include <limits>

#include "continuation/internal/branch_point_locator.hpp"
#include "core/solvers/bordered_system.hpp"
#include "core/solvers/eigen_newton.hpp"

namespace backbone::continuation::branch_point {

namespace {

// Forward-difference step for J's columns along unit directions at y (scaled unknowns): the
// square root of the machine epsilon, relative to y's largest entry once that exceeds 1.
double difference_step(const core::Vector& y) {
  return 1.5e-8 * std::max(1.0, y.lpNorm<Eigen::Infinity>());
}

// Secant updates of a chord matrix, B = J + A C^T (good Broyden, unit columns of C): the
// contact bar's residual is piecewise affine in u0, and where a step crosses into another piece
// its Jacobian differs from J by rank one (measured at the branch points of the contact bar at
// 100 intervals: the difference's second singular value is 1e-3..1e-5 of its first), so one
// update turns the chord into the piece's own matrix. PA = P A and RA = (I - J P) A, the part of
// A outside J's range, are kept with them (P: J's pseudo-inverse, Chord::solve).
struct SecantUpdates {
  static constexpr int max_updates = 6;
  SecantUpdates(Eigen::Index m, Eigen::Index n) : A(m, 0), C(n, 0), PA(n, 0), RA(m, 0) {}
  // The update that makes B map the step dx onto the change of the residual r_previous -> r,
  // unless B already does (to 1e-12 of that change).
  void add(const Chord& chord, const core::Vector& dx, const core::Vector& r,
           const core::Vector& r_previous);
  // The step dx = -P (r + A theta) + N c with theta = C^T dx and normal . dx = -plane (w =
  // N^T normal).
  core::Vector step(const Chord& chord, const core::Vector& w, const core::Vector& normal,
                    const core::Vector& r, double plane, double row_scale) const;
  core::Matrix A, C, PA, RA;
};

void SecantUpdates::add(const Chord& chord, const core::Vector& dx, const core::Vector& r,
                        const core::Vector& r_previous) {
  const core::Matrix& J = chord.jacobian;
  const double length = dx.norm();
  if (!(length > 0)) return;
  const core::Vector c = dx / length;
  const core::Vector Bc = J * c + A * (C.transpose() * c);
  const core::Vector a = (r - r_previous) / length - Bc;
  if (!(a.norm() > 1e-12 * (r - r_previous).norm() / length)) return;
  const Eigen::Index q = A.cols();
  A.conservativeResize(Eigen::NoChange, q + 1);
  C.conservativeResize(Eigen::NoChange, q + 1);
  PA.conservativeResize(Eigen::NoChange, q + 1);
  RA.conservativeResize(Eigen::NoChange, q + 1);
  A.col(q) = a;
  C.col(q) = c;
  PA.col(q) = chord.solve(a);
  RA.col(q) = a - J * PA.col(q);
}

core::Vector SecantUpdates::step(const Chord& chord, const core::Vector& w,
                                 const core::Vector& normal, const core::Vector& r, double plane,
                                 double row_scale) const {
  const core::Matrix& J = chord.jacobian;
  const core::Matrix& N = chord.null_space;
  const Eigen::Index m = J.rows(), k = N.cols();
  // The part of r + A theta outside J's range is made as small as it can be (rows scaled by
  // 1/|J| to the others' units), and (theta, c) is the least-squares solution of least norm.
  const core::Vector Pr = chord.solve(r);
  const Eigen::Index q = A.cols();
  core::Vector dx;
  if (q == 0) {
    dx = -Pr;
    dx += N * (w * ((-plane - normal.dot(dx)) / w.squaredNorm()));
    return dx;
  }
  core::Matrix S = core::Matrix::Zero(m + q + 1, q + k);
  core::Vector rhs(m + q + 1);
  S.topLeftCorner(m, q) = RA * row_scale;
  rhs.head(m) = -(r - J * Pr) * row_scale;
  S.block(m, 0, q, q) = core::Matrix::Identity(q, q) + C.transpose() * PA;
  S.block(m, q, q, k) = -C.transpose() * N;
  rhs.segment(m, q) = -C.transpose() * Pr;
  S.block(m + q, 0, 1, q) = normal.transpose() * PA;
  S.block(m + q, q, 1, k) = -w.transpose();
  rhs(m + q) = plane - normal.dot(Pr);
  const Eigen::CompleteOrthogonalDecomposition<core::Matrix> cod(S);
  const core::Vector u = cod.solve(rhs);
  dx = -Pr - PA * u.head(q) + N * u.tail(k);
  return dx;
}

}  // namespace

bool Locator::chord_correct(const Chord& chord, const core::Vector& normal,
                            const core::Vector& anchor, core::Vector& y, const core::Matrix* kinks,
                            bool polish) const {
  const core::Matrix& J = chord.jacobian;
  const core::Matrix& N = chord.null_space;
  const core::Vector w = N.transpose() * normal;
  if (!(w.squaredNorm() >= 0.25)) return false;
  const core::Vector f = factor();
  const core::Vector& rf = problem_.residual_factor();
  const double tolerance = options_.verification.corrector_options().residual_tolerance;
  SecantUpdates updates(J.rows(), J.cols());
  const double row_scale = 1.0 / std::max(J.norm(), std::numeric_limits<double>::min());
  // On failure y is left at the iterate with the smallest residual (a start for a corrector).
  core::Vector best = y;
  double best_norm = std::numeric_limits<double>::infinity();
  int without_progress = 0;
  // Polishing: the converged iterate with the smallest residual, and its norm.
  bool converged = false;
  core::Vector polished;
  double polished_norm = std::numeric_limits<double>::infinity();
  core::Vector r_previous, dx;
  for (int iteration = 0; iteration < 30; ++iteration) {
    core::Vector r;
    if (problem_.residual(y.cwiseQuotient(f), r) != core::EvalStatus::ok) break;
    const double plane = normal.dot(y - anchor);
    const bool within = r.lpNorm<Eigen::Infinity>() <= tolerance && std::abs(plane) <= tolerance;
    if (within && !polish) return true;
    if (rf.size() > 0) r = r.cwiseProduct(rf);
    if (within) {
      // Past the tolerance, steps go on while each cuts the residual tenfold.
      const double norm = r.norm();
      if (converged && !(norm <= 0.1 * polished_norm)) break;
      if (norm < polished_norm) {
        polished = y;
        polished_norm = norm;
      }
      converged = true;
    } else if (converged) {
      break;
    }
    // Linear convergence or none: two steps in a row that do not shrink the smallest residual
    // by 0.7 end it (the first step on a crossed piece does not; the update after it does).
    const double norm = r.norm();
    if (norm <= 0.7 * best_norm) {
      without_progress = 0;
    } else if (++without_progress >= 2) {
      break;
    }
    if (norm < best_norm) {
      best = y;
      best_norm = norm;
    }
    if (iteration == 0 && kinks && kinks->cols() > 0) {
      if (!difference_kinks(chord, *kinks, y, r, updates.A)) return false;
      updates.C = *kinks;
      updates.PA = chord.solve(updates.A);
      updates.RA = updates.A - J * updates.PA;
    } else if (iteration > 0 && updates.A.cols() < SecantUpdates::max_updates) {
      updates.add(chord, dx, r, r_previous);
    }
    dx = updates.step(chord, w, normal, r, plane, row_scale);
    r_previous = r;
    y += dx;
    if (!y.allFinite()) break;
  }
  y = converged ? polished : best;
  return converged;
}

bool Locator::difference_kinks(const Chord& chord, const core::Matrix& kinks, const core::Vector& y,
                               const core::Vector& r, core::Matrix& A) const {
  // J's columns along the kink directions, differenced at y (one residual each), less J's own.
  const core::Matrix& J = chord.jacobian;
  const core::Vector f = factor();
  const core::Vector& rf = problem_.residual_factor();
  const double h = difference_step(y);
  const Eigen::Index q = kinks.cols();
  A.resize(J.rows(), q);
  for (Eigen::Index i = 0; i < q; ++i) {
    core::Vector ri;
    if (problem_.residual((y + h * kinks.col(i)).cwiseQuotient(f), ri) != core::EvalStatus::ok)
      return false;
    if (rf.size() > 0) ri = ri.cwiseProduct(rf);
    A.col(i) = (ri - r) / h - J * kinks.col(i);
  }
  return true;
}

bool Locator::subspace_correct(const Chord& chord, const core::Vector& normal,
                               const core::Vector& anchor, core::Vector& y_io,
                               int max_differences) const {
  // On failure y_io is left as it was.
  core::Vector y = y_io;
  const core::Matrix& N = chord.null_space;
  if (N.cols() == 0) return false;
  const core::Vector f = factor();
  const core::Vector& rf = problem_.residual_factor();
  // The verification's own standard (a probe is a solution like a point of the branch), not the
  // corrector's tenth of it: the residual is evaluated at the point returned, so no margin is
  // needed, and the differenced matrix stalls at 1e-9..2e-8 (the finite-difference noise of the
  // near-null directions), just above a tenth of 3e-9 (the contact bar at 100 intervals).
  const double tolerance = options_.verification.residual_tolerance;
  const auto residual = [&](const core::Vector& at, core::Vector& r) {
    if (problem_.residual(at.cwiseQuotient(f), r) != core::EvalStatus::ok) return false;
    if (rf.size() > 0) r = r.cwiseProduct(rf);
    return r.allFinite();
  };
  const core::Matrix JN_chord = chord.jacobian * N;
  const auto converged = [&](const core::Vector& r, double plane) {
    const double local =
        rf.size() > 0 ? r.cwiseQuotient(rf).lpNorm<Eigen::Infinity>() : r.lpNorm<Eigen::Infinity>();
    return local <= tolerance && std::abs(plane) <= tolerance;
  };
  core::Vector r;
  if (!residual(y, r)) return false;
  double plane = normal.dot(y - anchor);
  if (converged(r, plane)) {
    y_io = y;
    return true;
  }
  // The matrix J + (JN - J N) N^T with the N columns differenced at an iterate is kept while
  // its steps halve |F| (one residual each); a step that does not re-differences them at the
  // iterate (N.cols() residuals); a step on fresh differences that does not halve |F| ends it.
  core::Matrix bordered;
  bool difference = true;
  int differenced = 0;
  for (int step = 0; step < 4 * max_differences; ++step) {
    const bool fresh = difference;
    if (difference) {
      // (Re-)difference along N at y (one residual each).
      if (differenced == max_differences) return false;
      ++differenced;
      const double h = difference_step(y);
      core::Matrix JN(r.size(), N.cols());
      for (Eigen::Index k = 0; k < N.cols(); ++k) {
        core::Vector rk;
        if (!residual(y + h * N.col(k), rk)) return false;
        JN.col(k) = (rk - r) / h;
      }
      bordered.resize(r.size() + 1, y.size());
      bordered.topRows(r.size()) = chord.jacobian + (JN - JN_chord) * N.transpose();
      bordered.row(r.size()) = normal.transpose();
      difference = false;
    }
    core::Vector rhs(r.size() + 1);
    rhs << -r, -plane;
    core::Vector dx;
    core::minimum_norm_solve(bordered, rhs, options_.rank.relative_threshold, dx);
    if (!dx.allFinite()) return false;
    const core::Vector y_new = y + dx;
    core::Vector r_new;
    if (!residual(y_new, r_new)) return false;
    const double plane_new = normal.dot(y_new - anchor);
    if (converged(r_new, plane_new)) {
      y_io = y_new;
      return true;
    }
    const auto size = [&](const core::Vector& v) {
      return rf.size() > 0 ? v.cwiseQuotient(rf).lpNorm<Eigen::Infinity>()
                           : v.lpNorm<Eigen::Infinity>();
    };
    if (size(r_new) <= 0.5 * size(r)) {
      y = y_new;
      r = r_new;
      plane = plane_new;
      continue;
    }
    if (fresh) return false;
    difference = true;
  }
  return false;
}

}  // namespace backbone::continuation::branch_point
