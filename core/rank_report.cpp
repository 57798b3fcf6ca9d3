#include "core/rank_report.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/bordered_system.hpp"
#include "core/errors.hpp"
#include "core/finite_difference.hpp"
#include "core/sparse_least_squares.hpp"

namespace backbone::core {

void RankOptions::validate() const {
  if (!(relative_threshold > 0 && relative_threshold < 1))
    throw InputError("rank.relative_threshold",
                     fmt::format("must be in (0, 1) (got {})", relative_threshold));
  if (!(absolute_threshold >= 0) || !std::isfinite(absolute_threshold))
    throw InputError("rank.absolute_threshold",
                     fmt::format("must be finite and >= 0 (got {})", absolute_threshold));
}

void VerifyOptions::validate() const {
  if (!(step > 0) || !std::isfinite(step))
    throw InputError("verify.step", fmt::format("must be finite and > 0 (got {})", step));
  if (!(residual_tolerance > 0) || !std::isfinite(residual_tolerance))
    throw InputError("verify.residual_tolerance",
                     fmt::format("must be finite and > 0 (got {})", residual_tolerance));
  if (!(drift_ratio > 0 && drift_ratio < 1))
    throw InputError("verify.drift_ratio", fmt::format("must be in (0, 1) (got {})", drift_ratio));
  if (max_iterations < 1)
    throw InputError("verify.max_iterations", fmt::format("must be >= 1 (got {})", max_iterations));
  if (!(corrector_tolerance_ratio > 0 && corrector_tolerance_ratio <= 1))
    throw InputError("verify.corrector_tolerance_ratio",
                     fmt::format("must be in (0, 1] (got {})", corrector_tolerance_ratio));
}

NewtonOptions VerifyOptions::corrector_options() const {
  NewtonOptions newton;
  newton.residual_tolerance = corrector_tolerance_ratio * residual_tolerance;
  newton.max_iterations = max_iterations;
  // Chord steps on a probe's fresh Jacobian while they contract (core/README.md, 'Rank
  // reports': 146 -> 106 Jacobians on the contact bar's grazing start at N = 320).
  newton.reuse_jacobian = true;
  // Damped sparse steps where the probe's bordered system keeps the family's other null
  // directions (core/README.md, 'Rank reports').
  newton.damped_sparse = true;
  return newton;
}

std::unique_ptr<Corrector> make_verifier(const VerifyOptions& options) {
  options.validate();
  return make_corrector("eigen", options.corrector_options());
}

namespace {

// threshold, rank, nullity and gap from the descending singular values (entry 0 sigma_max;
// entries not computed are NaN and count as kept).
void count_rank(RankReport& report, const RankOptions& options, Eigen::Index n) {
  const Vector& sv = report.singular_values;
  const double sigma_max = sv.size() > 0 ? sv[0] : 0.0;
  report.threshold = std::max(options.relative_threshold * sigma_max, options.absolute_threshold);
  int rank = 0;
  for (Eigen::Index i = 0; i < sv.size(); ++i)
    if (!(sv[i] <= report.threshold)) ++rank;  // NaN (not computed) lies above the threshold
  report.rank = rank;
  report.nullity = static_cast<int>(n) - rank;
  if (rank == 0) {
    report.gap = 0;
  } else if (rank < sv.size() && sv[rank] > 0) {
    report.gap = sv[rank - 1] / sv[rank];
  } else {
    report.gap = std::numeric_limits<double>::infinity();
  }
}

// A fixed, well-spread start block (n x k): entries +-(1..2) (fixed_weight), orthonormalised.
Matrix start_block(Eigen::Index n, Eigen::Index k) {
  Matrix X(n, k);
  for (Eigen::Index j = 0; j < k; ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      X(i, j) = fixed_weight(static_cast<std::uint64_t>(j * n + i + 1));
  const Eigen::HouseholderQR<Matrix> qr(X);
  return qr.householderQ() * Matrix::Identity(n, k);
}

// A with A^T A = J^T J, the operator the iteration below works with: R of a Householder QR of J
// (n x n), or, for a sparse J (sparse_least_squares.hpp), J itself with a sparse Cholesky
// factor of J^T J + mu I for the inverse iteration (mu = 1e-10 of its largest diagonal entry:
// the same eigenvectors, J^T J itself being singular wherever there is a null direction).
struct TriangularGram {
  Matrix r;
  Eigen::Index rows() const { return r.rows(); }
  Vector times(const Vector& v) const { return r.triangularView<Eigen::Upper>() * v; }
  Matrix times(const Matrix& x) const { return r.triangularView<Eigen::Upper>() * x; }
  Vector times_transpose(const Vector& u) const {
    return r.triangularView<Eigen::Upper>().transpose() * u;
  }
  Matrix inverse_gram(const Matrix& x) const {
    const auto upper = r.triangularView<Eigen::Upper>();
    return upper.solve(Matrix(upper.transpose().solve(x)));
  }
};

struct SparseGram {
  Eigen::SparseMatrix<double> a;
  NormalFactor factor;
  Eigen::Index rows() const { return a.rows(); }
  Vector times(const Vector& v) const { return a * v; }
  Matrix times(const Matrix& x) const { return a * x; }
  Vector times_transpose(const Vector& u) const { return a.transpose() * u; }
  Matrix inverse_gram(const Matrix& x) const { return factor.solve(x); }
};

template <class Gram>
bool smallest_singular_values(const Gram& gram, Eigen::Index n, const RankOptions& options,
                              RankReport& report);

// The smallest singular values of J (m >= n) and their right vectors, without a full SVD:
// R from a Householder QR of J (J = QR, same singular values and right vectors), sigma_max by
// Lanczos bidiagonalisation of R, the k smallest by block inverse iteration on R^T R (two
// triangular solves per step, the block re-orthonormalised) with a Rayleigh-Ritz step (SVD of
// the n x k R X) each time, converged when the span of the values at or below the threshold
// and the smallest value above it stop moving (below). The block holds k = 8 to start and
// doubles while the values at or below the threshold fill all but one of it, so that it always
// holds one value above the threshold (sigma_kept and the gap). False (the caller takes the
// full SVD) when R is singular to working precision, the block would exceed n / 2, or 60 steps
// do not converge. Measured on the contact bar's mode 1 at N = 160 (321 x 161): 4-7 steps,
// sigma_zero and sigma_kept within 3.4e-6 of the full SVD's (sigma_max's Lanczos estimate),
// the same branch and dimensions; core/README.md, 'Rank reports'. A sparse J without dense
// rows skips the QR: the products are J's, the inverse iteration a sparse Cholesky solve
// (SparseGram); should that not converge, the QR is taken after all.
bool smallest_singular_values(const Matrix& J, const RankOptions& options, RankReport& report) {
  const Eigen::Index n = J.cols();
  if (J.rows() < n || n < 4) return false;
  {
    // Sparse without dense rows (those would make J^T J dense): no QR at all.
    SparseGram sparse;
    std::vector<char> dense_row;
    if (sparse_view(J, sparse.a, dense_row) &&
        std::find(dense_row.begin(), dense_row.end(), 1) == dense_row.end() &&
        factor_shifted_normal(sparse.a, sparse.factor) &&
        smallest_singular_values(sparse, n, options, report))
      return true;
  }
  const Eigen::HouseholderQR<Matrix> qr(J);
  TriangularGram triangular{qr.matrixQR().topRows(n).triangularView<Eigen::Upper>()};
  const double largest_pivot = triangular.r.diagonal().cwiseAbs().maxCoeff();
  if (!(largest_pivot > 0) || !std::isfinite(largest_pivot) ||
      !(triangular.r.diagonal().cwiseAbs().minCoeff() > 1e-15 * largest_pivot))
    return false;
  return smallest_singular_values(triangular, n, options, report);
}

template <class Gram>
bool smallest_singular_values(const Gram& gram, Eigen::Index n, const RankOptions& options,
                              RankReport& report) {
  // sigma_max: Golub-Kahan-Lanczos bidiagonalisation of R (fully reorthogonalised), the largest
  // singular value of its bidiagonal, until that moves by less than 1e-10 of itself (at most
  // 60 steps; Lanczos finds the extreme values in a few tens of steps where power iteration on
  // a clustered top of the spectrum took hundreds, and left 0.3 % on the contact bar).
  double sigma_max = 0;
  {
    const int steps = static_cast<int>(std::min<Eigen::Index>(60, n));
    Matrix V(n, steps + 1), U(gram.rows(), steps);
    Vector alpha = Vector::Zero(steps), beta = Vector::Zero(steps);
    V.col(0) = start_block(n, 1).col(0);
    for (int j = 0; j < steps; ++j) {
      Vector u = gram.times(Vector(V.col(j)));
      if (j > 0) u -= beta[j - 1] * U.col(j - 1);
      u -= U.leftCols(j) * (U.leftCols(j).transpose() * u);
      alpha[j] = u.norm();
      if (!(alpha[j] > 0) || !std::isfinite(alpha[j])) break;
      U.col(j) = u / alpha[j];
      Vector w = gram.times_transpose(Vector(U.col(j))) - alpha[j] * V.col(j);
      w -= V.leftCols(j + 1) * (V.leftCols(j + 1).transpose() * w);
      beta[j] = w.norm();
      // The largest eigenvalue of the tridiagonal B^T B (B: alpha on the diagonal, beta above).
      Vector diagonal(j + 1), off(j);
      for (int i = 0; i <= j; ++i) {
        diagonal[i] = alpha[i] * alpha[i] + (i > 0 ? beta[i - 1] * beta[i - 1] : 0.0);
        if (i < j) off[i] = alpha[i] * beta[i];
      }
      Eigen::SelfAdjointEigenSolver<Matrix> tridiagonal;
      tridiagonal.computeFromTridiagonal(diagonal, off, Eigen::EigenvaluesOnly);
      const double estimate = std::sqrt(tridiagonal.eigenvalues()[j]);
      const bool settled = std::abs(estimate - sigma_max) <= 1e-10 * estimate;
      sigma_max = estimate;
      if (settled || !(beta[j] > 1e-15 * estimate)) break;
      V.col(j + 1) = w / beta[j];
    }
  }
  if (!(sigma_max > 0) || !std::isfinite(sigma_max)) return false;
  const double threshold =
      std::max(options.relative_threshold * sigma_max, options.absolute_threshold);

  for (Eigen::Index k = std::min<Eigen::Index>(8, n); 2 * k <= n; k *= 2) {
    Matrix X = start_block(n, k);
    bool converged = false, too_small = false;
    Vector s;
    Matrix W, previous_span;
    int previous_below = -1;
    double previous_kept = 0;
    for (int step = 0; step < 60 && !converged; ++step) {
      Matrix Y = gram.inverse_gram(X);
      if (!Y.allFinite()) return false;
      const Eigen::HouseholderQR<Matrix> block(Y);
      X = block.householderQ() * Matrix::Identity(n, k);
      const Eigen::JacobiSVD<Matrix> ritz(gram.times(X), Eigen::ComputeThinU | Eigen::ComputeThinV);
      s = ritz.singularValues();
      W = X * ritz.matrixV();
      int below = 0;
      for (Eigen::Index i = 0; i < k; ++i) below += s[i] <= threshold ? 1 : 0;
      too_small = below >= k - 1;
      if (too_small) break;
      // The pairs that matter: those at or below the threshold (their span) and the smallest
      // above it (its value). Converged when the span moves by a sine below 1e-10 between two
      // steps and that value by 1e-10 of itself: each step shrinks the error of both by
      // (s / sigma_{k+1})^2, so what is left is below that last move once the ratio is below
      // 1/2 (the block is eight or more wide). (A residual test |R^T u - s w| does not work
      // for the values at the finite-difference noise: u = R w / s divides R w's round-off,
      // eps sigma_max, by s.)
      const Eigen::Index kept = k - 1 - below;
      const Matrix null_span = W.rightCols(below);
      converged =
          below == previous_below && previous_kept > 0 &&
          std::abs(s[kept] - previous_kept) <= 1e-10 * s[kept] &&
          (below == 0 || (previous_span - null_span * (null_span.transpose() * previous_span))
                                 .colwise()
                                 .norm()
                                 .maxCoeff() <= 1e-10);
      previous_below = below;
      previous_kept = s[kept];
      previous_span = null_span;
    }
    if (too_small) continue;
    if (!converged) return false;
    report.singular_values = Vector::Constant(n, std::numeric_limits<double>::quiet_NaN());
    report.singular_values[0] = sigma_max;
    report.singular_values.tail(k) = s;
    count_rank(report, options, n);
    report.null_directions = W.rightCols(report.nullity);
    return true;
  }
  return false;
}

}  // namespace

RankReport rank_report(const Matrix& J, const RankOptions& options) {
  options.validate();
  const Eigen::Index n = J.cols();
  RankReport report;
  report.relative_threshold = options.relative_threshold;
  if (!options.full_spectrum && smallest_singular_values(J, options, report)) return report;
  // Full V: for m < n the null space includes the n - m directions without a singular value.
  Eigen::BDCSVD<Matrix> svd(J, Eigen::ComputeFullV);
  report.singular_values = svd.singularValues();
  count_rank(report, options, n);
  report.null_directions = svd.matrixV().rightCols(report.nullity);
  return report;
}

std::string RankReport::summary() const {
  const double sigma_max = singular_values.size() > 0 ? singular_values[0] : 0.0;
  const std::string verified =
      verified_dimension >= 0 ? fmt::format(" (verified {})", verified_dimension) : "";
  return fmt::format(
      "rank {}/{}, nullity {}{}, sigma_max {:.3e}, threshold {:.3e} (relative {:.1e}), gap "
      "{:.3e}",
      rank, rank + nullity, nullity, verified, sigma_max, threshold, relative_threshold, gap);
}

namespace {

struct Probe {
  bool converged = false;
  Vector secant;                                           // (corrected point - x) / h
  double drift = std::numeric_limits<double>::infinity();  // |corrected - stepped| / h
};

// The probe's constrained system, whose Jacobian is refused (EvalStatus::failed, which ends
// the correction) at iterates farther than `radius` from x. A probe's end is used only within
// |h| / drift_ratio of x (found_neighbour needs it within drift_ratio |h| of the stepped point,
// and the rotation takes secants up to 1 / drift_ratio long): a correction that has wandered
// beyond that is not expected back, and its further Jacobians were most of the cost of a
// rank report on a many-dimensional family (core/README.md, 'Rank reports'). Residuals (line
// searches, chord steps) stay allowed.
class ProbeRegion : public Problem {
 public:
  ProbeRegion(const Problem& constrained, const Vector& x, double radius)
      : constrained_(constrained), center_(x), radius_(radius) {}
  int num_unknowns() const override { return constrained_.num_unknowns(); }
  int num_equations() const override { return constrained_.num_equations(); }
  std::string name() const override { return constrained_.name(); }
  Vector typical_scale() const override { return constrained_.typical_scale(); }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    return constrained_.residual(x, r);
  }
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override {
    if (!((x - center_).norm() <= radius_)) return EvalStatus::failed;
    return constrained_.jacobian(x, J);
  }

 private:
  const Problem& constrained_;
  const Vector& center_;
  double radius_;
};

// J(x) as the start of the probes' chord steps, while it serves. At a kink of F (the contact
// bar's grazing start) J(x) mixes the two sides and no probe's first chord step on it pays, yet
// each probe factorised it (a dense QR of the bordered system, whose other null directions keep
// it off the sparse path): once two probes have needed a fresh Jacobian and none has been
// corrected on J(x) alone, the later probes start with a fresh one (core/README.md, 'Rank
// reports').
struct ChordStart {
  const Matrix* jacobian_at_x = nullptr;
  int refused = 0, served = 0;
  const Matrix* jacobian() const { return refused >= 2 && served == 0 ? nullptr : jacobian_at_x; }
  void record(const NewtonSummary& s) {
    if (s.jacobian_evaluations == 0)
      ++served;
    else
      ++refused;
  }
};

// Steps from x by h along d, re-corrects on the hyperplane through the stepped point.
Probe probe(const Problem& problem, const Vector& x, const Vector& d, double h,
            Corrector& corrector, const VerifyOptions& options, ChordStart& start) {
  Probe result;
  const Vector stepped = x + h * d;
  const BorderedSystem bordered(problem, {BorderRow::hyperplane(d, stepped)});
  const ProbeRegion constrained(bordered, x, std::abs(h) / options.drift_ratio);
  Vector y = stepped;
  Matrix nearby;
  const Matrix* base = start.jacobian();
  const bool chord =
      base && bordered.jacobian_with_base(stepped, *base, nearby) == EvalStatus::ok;
  const NewtonSummary s =
      chord ? corrector.solve(constrained, y, nearby) : corrector.solve(constrained, y);
  if (chord) start.record(s);
  if (!y.allFinite()) return result;
  Vector f;
  // Judge the corrected point by F itself (the corrector's own tolerance may be looser).
  if (problem.residual(y, f) != EvalStatus::ok) return result;
  result.converged =
      (s.converged() || s.status == NewtonStatus::stalled) &&
      f.lpNorm<Eigen::Infinity>() <= options.residual_tolerance &&
      std::abs(d.dot(y - stepped)) <= options.residual_tolerance + 1e-12 * std::abs(h);
  result.secant = (y - x) / h;
  result.drift = (y - stepped).norm() / std::abs(h);
  return result;
}

bool found_neighbour(const Probe& p, const VerifyOptions& options) {
  return p.converged && p.drift <= options.drift_ratio;
}

// A probe's verdict from a solution z already known near x (the branch's previous point), as
// if a probe had stepped by h = d . (z - x) and been corrected onto z: the same tests of F(z)
// and of the drift (the caller has checked ||F(z)||_inf <= residual_tolerance, once).
Probe known_neighbour(const Vector& x, const Vector& d, const Vector& z) {
  Probe result;
  const Vector e = z - x;
  const double h = d.dot(e);
  if (!(std::abs(h) > 0) || !std::isfinite(h)) return result;
  result.converged = true;
  result.secant = e / h;
  result.drift = (e - h * d).norm() / std::abs(h);
  return result;
}

// Probes along +d, and along -d when +d finds no neighbour: at a point on the boundary of a
// manifold (a grazing limit of a continuum) only one side holds solutions.
Probe probe_either_side(const Problem& problem, const Vector& x, const Vector& d, double h,
                        Corrector& corrector, const VerifyOptions& options,
                        ChordStart& start) {
  Probe forward = probe(problem, x, d, h, corrector, options, start);
  if (found_neighbour(forward, options)) return forward;
  Probe backward = probe(problem, x, d, -h, corrector, options, start);
  return found_neighbour(backward, options) ? backward : forward;
}

}  // namespace

void verify_null_directions(const Problem& problem, const Vector& x, Corrector& corrector,
                            const VerifyOptions& options, RankReport& report,
                            const Matrix* jacobian_at_x, const Vector* neighbour) {
  options.validate();
  const int n = problem.num_unknowns();
  if (x.size() != n || report.null_directions.rows() != n)
    throw InputError("verify", fmt::format("sizes do not match: x has {} entries, null "
                                           "directions {} rows, problem {} unknowns",
                                           x.size(), report.null_directions.rows(), n));
  const int k = static_cast<int>(report.null_directions.cols());
  report.direction_verified.assign(static_cast<std::size_t>(k), false);
  report.verified_dimension = 0;
  if (k == 0) return;

  const Vector scale = problem.typical_scale().cwiseAbs();
  // Step length in the problem's units: `step` times the typical scale seen along d.
  auto step_along = [&](const Vector& d) {
    const double s = d.cwiseProduct(scale).norm();
    return options.step * (s > 0 ? s : 1.0);
  };

  // A known neighbour stands in for the probe of the direction it verifies.
  bool neighbour_ok = false;
  if (neighbour && neighbour->size() == n && neighbour->allFinite()) {
    Vector f;
    neighbour_ok = problem.residual(*neighbour, f) == EvalStatus::ok &&
                   f.lpNorm<Eigen::Infinity>() <= options.residual_tolerance;
  }
  ChordStart start{jacobian_at_x};
  const auto probe_direction = [&](const Vector& d) {
    if (neighbour_ok) {
      Probe known = known_neighbour(x, d, *neighbour);
      if (found_neighbour(known, options)) return known;
    }
    return probe_either_side(problem, x, d, step_along(d), corrector, options, start);
  };

  // Pass 1: probe the candidate basis as given.
  Matrix D = report.null_directions;
  std::vector<Probe> first(static_cast<std::size_t>(k));
  bool all_verified = true;
  for (int i = 0; i < k; ++i) {
    auto& p = first[static_cast<std::size_t>(i)];
    p = probe_direction(D.col(i));
    all_verified = all_verified && found_neighbour(p, options);
  }
  if (all_verified) {
    report.direction_verified.assign(static_cast<std::size_t>(k), true);
    report.verified_dimension = k;
    return;
  }

  // The candidate space N may be larger than the tangent space T of the solution set, and
  // the SVD's basis of N need not be aligned with T (a double root has J = 0 and V = I). Each
  // converged probe whose secant is not too long (the hyperplane met the solution set near
  // the stepped point, possibly obliquely) gives a secant close to T. The directions that
  // found a neighbour stay as they are (verified); the basis of the span of the others is
  // rotated so that its first columns span those secants' components in it, and probed again:
  // along the rotated directions the drift criterion is meaningful. (Rotating and probing
  // the whole basis again also re-probed what pass 1 had verified, and could lose some of it:
  // 23 verified on the contact bar's grazing start at N = 320 where this keeps 26 of 32.)
  std::vector<int> order;  // the passed directions first, then the others
  for (const bool passed : {true, false})
    for (int i = 0; i < k; ++i)
      if (found_neighbour(first[static_cast<std::size_t>(i)], options) == passed)
        order.push_back(i);
  const int verified_before =
      k - static_cast<int>(std::count_if(first.begin(), first.end(), [&](const Probe& p) {
        return !found_neighbour(p, options);
      }));
  const int r = k - verified_before;
  Matrix rotated(n, k);
  for (int c = 0; c < k; ++c) rotated.col(c) = D.col(order[static_cast<std::size_t>(c)]);
  Matrix secants(r, r);
  int good = 0;
  for (int c = verified_before; c < k; ++c) {
    const auto& p = first[static_cast<std::size_t>(order[static_cast<std::size_t>(c)])];
    if (p.converged && p.secant.norm() <= 1.0 / options.drift_ratio)
      secants.col(good++) = rotated.rightCols(r).transpose() * p.secant;  // in their span
  }
  if (good > 0) {
    Eigen::JacobiSVD<Matrix> svd(secants.leftCols(good), Eigen::ComputeFullU);
    // Still an orthonormal basis of their span, principal secants first.
    rotated.rightCols(r) = (rotated.rightCols(r) * svd.matrixU()).eval();
  }
  report.direction_verified.assign(static_cast<std::size_t>(k), false);
  int verified = 0;
  for (int c = 0; c < k; ++c) {
    const bool real =
        c < verified_before || found_neighbour(probe_direction(rotated.col(c)), options);
    report.direction_verified[static_cast<std::size_t>(c)] = real;
    verified += real ? 1 : 0;
  }
  report.null_directions = rotated;
  report.verified_dimension = verified;
}

RankReport rank_report_beside(const Problem& problem, const Vector& x, const Vector& into,
                              double step, const RankOptions& options) {
  RankReport best;
  best.null_directions = Matrix(x.size(), 0);
  const double norm = into.norm();
  if (into.size() != x.size() || !(norm > 0) || !std::isfinite(norm)) return best;
  for (const double side : {1.0, -1.0}) {
    Matrix J;
    if (problem.jacobian(x + (side * step / norm) * into, J) != EvalStatus::ok) continue;
    RankReport there = rank_report(J, options);
    if (there.nullity > best.nullity) best = std::move(there);
  }
  return best;
}

}  // namespace backbone::core
