#include "core/rank/probes.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/errors.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/bordered_system.hpp"

namespace backbone::core {

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

std::unique_ptr<Corrector> make_verifier(const VerifyOptions& options, const RankOptions& rank) {
  options.validate();
  rank.validate();
  NewtonOptions newton = options.corrector_options();
  newton.rank_cutoff = rank.relative_threshold;
  return make_corrector("eigen", newton);
}

namespace {

struct Probe {
  bool converged = false;
  Vector secant;                                               // (corrected point - x) / h
  double drift = std::numeric_limits<double>::infinity();      // |corrected - stepped| / h
  double residual = std::numeric_limits<double>::quiet_NaN();  // ||F||_inf there
  Vector point;                                                // the corrected point
};

// The probe's constrained system, whose Jacobian is refused (EvalStatus::failed, which ends
// the correction) at iterates farther than `radius` from x. A probe's end is used only within
// |h| / drift_ratio of x (found_neighbour needs it within drift_ratio |h| of the stepped point,
// and the rotation takes secants up to 1 / drift_ratio long): a correction that has wandered
// beyond that is not expected back, and its further Jacobians are most of the cost of a
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
  result.point = y;
  Vector f;
  // Judge the corrected point by F itself (the corrector's own tolerance may be looser).
  if (problem.residual(y, f) != EvalStatus::ok) return result;
  result.residual = f.lpNorm<Eigen::Infinity>();
  result.converged =
      (s.converged() || s.status == NewtonStatus::stalled) &&
      result.residual <= options.residual_tolerance &&
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

// The probes of one verify_null_directions call: a direction by the known neighbour when that
// verifies it, else by probe_either_side with a step of `step` times the typical scale seen along
// it. One ChordStart for all of them.
class DirectionProbes {
 public:
  DirectionProbes(const Problem& problem, const Vector& x, Corrector& corrector,
                  const VerifyOptions& options, const Matrix* jacobian_at_x,
                  const Vector* neighbour, double neighbour_residual)
      : problem_(problem),
        x_(x),
        corrector_(corrector),
        options_(options),
        scale_(problem.typical_scale().cwiseAbs()),
        start_{jacobian_at_x} {
    if (neighbour && neighbour->size() == problem.num_unknowns() && neighbour->allFinite()) {
      neighbour_ = neighbour;
      neighbour_residual_ = neighbour_residual;
    }
  }

  Probe operator()(const Vector& d) {
    // A known neighbour stands in for the probe of the direction it verifies; its residual is
    // evaluated (once) only when the drift test passes and the caller did not give it.
    if (neighbour_) {
      Probe known = known_neighbour(x_, d, *neighbour_);
      if (found_neighbour(known, options_) && neighbour_is_solution()) return known;
    }
    return probe_either_side(problem_, x_, d, step_along(d), corrector_, options_, start_);
  }

 private:
  // Step length in the problem's units: `step` times the typical scale seen along d.
  double step_along(const Vector& d) const {
    const double s = d.cwiseProduct(scale_).norm();
    return options_.step * (s > 0 ? s : 1.0);
  }

  const Problem& problem_;
  const Vector& x_;
  Corrector& corrector_;
  const VerifyOptions& options_;
  const Vector scale_;
  bool neighbour_is_solution() {
    if (std::isnan(neighbour_residual_)) {
      Vector f;
      neighbour_residual_ = problem_.residual(*neighbour_, f) == EvalStatus::ok
                                ? f.lpNorm<Eigen::Infinity>()
                                : std::numeric_limits<double>::infinity();
    }
    return neighbour_residual_ <= options_.residual_tolerance;
  }

  const Vector* neighbour_ = nullptr;
  double neighbour_residual_ = std::numeric_limits<double>::quiet_NaN();
  ChordStart start_;
};

// The candidate space N may be larger than the tangent space T of the solution set, and the
// SVD's basis of N need not be aligned with T (a double root has J = 0 and V = I). Each
// converged probe whose secant is not too long (the hyperplane met the solution set near the
// stepped point, possibly obliquely) gives a secant close to T. The directions D that found a
// neighbour (first: their probes) come first, as they are (verified_before of them); the basis
// of the span of the others follows, rotated so that its first columns span those secants'
// components in it (still orthonormal, principal secants first): along the rotated directions
// the drift criterion is meaningful. Rotating only the others keeps every direction the first
// probes verified.
Matrix passed_then_rotated(const Matrix& D, const std::vector<Probe>& first,
                           const VerifyOptions& options, int& verified_before) {
  const int n = static_cast<int>(D.rows());
  const int k = static_cast<int>(D.cols());
  std::vector<int> order;  // the passed directions first, then the others
  for (const bool passed : {true, false})
    for (int i = 0; i < k; ++i)
      if (found_neighbour(first[static_cast<std::size_t>(i)], options) == passed)
        order.push_back(i);
  verified_before =
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
    rotated.rightCols(r) = (rotated.rightCols(r) * svd.matrixU()).eval();
  }
  return rotated;
}

}  // namespace

NeighbourProbe probe_neighbour(const Problem& problem, const Vector& x, const Vector& d, double h,
                               Corrector& corrector, const VerifyOptions& options) {
  ChordStart fresh;
  const Probe p = probe(problem, x, d, h, corrector, options, fresh);
  NeighbourProbe out;
  out.converged = p.converged;
  out.found = found_neighbour(p, options);
  out.residual = p.residual;
  out.drift = p.drift;
  out.point = p.point;
  return out;
}

void verify_null_directions(const Problem& problem, const Vector& x, Corrector& corrector,
                            const VerifyOptions& options, RankReport& report,
                            const Matrix* jacobian_at_x, const Vector* neighbour,
                            double neighbour_residual) {
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
  DirectionProbes probe_direction(problem, x, corrector, options, jacobian_at_x, neighbour,
                                  neighbour_residual);

  // Pass 1: probe the candidate basis as given.
  const Matrix D = report.null_directions;
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

  // Pass 2: the directions that failed, rotated onto the secants of their probes, again.
  int verified_before = 0;
  const Matrix rotated = passed_then_rotated(D, first, options, verified_before);
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

}  // namespace backbone::core
