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
#include "core/few_singular_values.hpp"
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

}  // namespace

RankReport rank_report(const Matrix& J, const RankOptions& options) {
  options.validate();
  const Eigen::Index n = J.cols();
  RankReport report;
  report.relative_threshold = options.relative_threshold;
  SmallestSingularValues few;
  if (!options.full_spectrum &&
      smallest_singular_values(J, options.relative_threshold, options.absolute_threshold, few)) {
    report.singular_values = Vector::Constant(n, std::numeric_limits<double>::quiet_NaN());
    report.singular_values[0] = few.largest;
    report.singular_values.tail(few.values.size()) = few.values;
    count_rank(report, options, n);
    report.null_directions = few.right.rightCols(report.nullity);
    return report;
  }
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
  const bool chord = base && bordered.jacobian_with_base(stepped, *base, nearby) == EvalStatus::ok;
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
                        Corrector& corrector, const VerifyOptions& options, ChordStart& start) {
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
