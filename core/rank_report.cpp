#include "core/rank_report.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "core/bordered_system.hpp"
#include "core/errors.hpp"

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
  return newton;
}

std::unique_ptr<Corrector> make_verifier(const VerifyOptions& options) {
  options.validate();
  return make_corrector("eigen", options.corrector_options());
}

RankReport rank_report(const Matrix& J, const RankOptions& options) {
  options.validate();
  const Eigen::Index n = J.cols();
  RankReport report;
  report.relative_threshold = options.relative_threshold;
  // Full V: for m < n the null space includes the n - m directions without a singular value.
  Eigen::BDCSVD<Matrix> svd(J, Eigen::ComputeFullV);
  report.singular_values = svd.singularValues();
  const double sigma_max = report.singular_values.size() > 0 ? report.singular_values[0] : 0.0;
  report.threshold = std::max(options.relative_threshold * sigma_max, options.absolute_threshold);
  int rank = 0;
  for (Eigen::Index i = 0; i < report.singular_values.size(); ++i)
    if (report.singular_values[i] > report.threshold) ++rank;
  report.rank = rank;
  report.nullity = static_cast<int>(n) - rank;
  if (rank == 0) {
    report.gap = 0;
  } else if (rank < report.singular_values.size() && report.singular_values[rank] > 0) {
    report.gap = report.singular_values[rank - 1] / report.singular_values[rank];
  } else {
    report.gap = std::numeric_limits<double>::infinity();
  }
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

// Steps from x by h along d, re-corrects on the hyperplane through the stepped point.
Probe probe(const Problem& problem, const Vector& x, const Vector& d, double h,
            Corrector& corrector, const VerifyOptions& options, const Matrix* jacobian_at_x) {
  Probe result;
  const Vector stepped = x + h * d;
  const BorderedSystem constrained(problem, {BorderRow::hyperplane(d, stepped)});
  Vector y = stepped;
  Matrix nearby;
  const NewtonSummary s = jacobian_at_x && constrained.jacobian_with_base(stepped, *jacobian_at_x,
                                                                          nearby) == EvalStatus::ok
                              ? corrector.solve(constrained, y, nearby)
                              : corrector.solve(constrained, y);
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

// Probes along +d, and along -d when +d finds no neighbour: at a point on the boundary of a
// manifold (a grazing limit of a continuum) only one side holds solutions.
Probe probe_either_side(const Problem& problem, const Vector& x, const Vector& d, double h,
                        Corrector& corrector, const VerifyOptions& options,
                        const Matrix* jacobian_at_x) {
  Probe forward = probe(problem, x, d, h, corrector, options, jacobian_at_x);
  if (found_neighbour(forward, options)) return forward;
  Probe backward = probe(problem, x, d, -h, corrector, options, jacobian_at_x);
  return found_neighbour(backward, options) ? backward : forward;
}

}  // namespace

void verify_null_directions(const Problem& problem, const Vector& x, Corrector& corrector,
                            const VerifyOptions& options, RankReport& report,
                            const Matrix* jacobian_at_x) {
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

  // Pass 1: probe the candidate basis as given.
  Matrix D = report.null_directions;
  std::vector<Probe> first(static_cast<std::size_t>(k));
  bool all_verified = true;
  for (int i = 0; i < k; ++i) {
    auto& p = first[static_cast<std::size_t>(i)];
    p = probe_either_side(problem, x, D.col(i), step_along(D.col(i)), corrector, options,
                          jacobian_at_x);
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
  // the stepped point, possibly obliquely) gives a secant close to T. Rotate the basis of N
  // so that its first columns span those secants, then probe again: along the rotated
  // directions the drift criterion is meaningful.
  Matrix secants(k, k);
  int good = 0;
  for (int i = 0; i < k; ++i) {
    const auto& p = first[static_cast<std::size_t>(i)];
    if (p.converged && p.secant.norm() <= 1.0 / options.drift_ratio)
      secants.col(good++) = D.transpose() * p.secant;  // coordinates in N
  }
  if (good > 0) {
    Eigen::JacobiSVD<Matrix> svd(secants.leftCols(good), Eigen::ComputeFullU);
    D = D * svd.matrixU();  // still an orthonormal basis of N, principal secants first
  }
  int verified = 0;
  for (int i = 0; i < k; ++i) {
    const Probe p = probe_either_side(problem, x, D.col(i), step_along(D.col(i)), corrector,
                                      options, jacobian_at_x);
    const bool real = found_neighbour(p, options);
    report.direction_verified[static_cast<std::size_t>(i)] = real;
    verified += real ? 1 : 0;
  }
  report.null_directions = D;
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
