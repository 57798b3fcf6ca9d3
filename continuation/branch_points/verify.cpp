#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "continuation/internal/branch_point_locator.hpp"
#include "core/rank/few_singular_values.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/bordered_system.hpp"

namespace backbone::continuation::branch_point {

// What the probes of one located point learn from each other: the directions along which J
// changes between the point and its probes (kinks, differenced at the next probes' starts), and
// how often the subspace stage finished a probe.
struct Locator::Probing {
  explicit Probing(Eigen::Index n) : kinks(n, 0) {}
  core::Matrix kinks;  // n x q, orthonormal, q <= 4
  int learned = 0;     // probes whose J(y) was compared with J (at most three)
  int subspace_done = 0, subspace_failed = 0;
};

void Locator::verify(BranchPointReport& report, const core::Vector& z, const core::Vector& tangent,
                     core::Matrix J, const Chord* chord_of_j) {
  // z, tangent and J in the unit scale; the loop's problem in its current units.
  const core::Vector f = factor();
  report.x = z.cwiseProduct(problem_.unit_scale());
  report.observables = problem_.base().observables(report.x);
  report.tangent_angle = std::numeric_limits<double>::quiet_NaN();
  if (J.size() == 0) {
    if (problem_.jacobian(z.cwiseQuotient(f), J) != core::EvalStatus::ok) return;
    J = in_unit_scale(J);
    chord_of_j = nullptr;
  }
  const core::Vector t = tangent.normalized();
  int candidates = 0;
  const core::Matrix directions = directions_beyond(J, t, report, candidates);
  if (report.nullity < 1) return;
  // One probe per candidate direction d: step by h along d and re-correct on the hyperplane
  // through the stepped point orthogonal to d (probe()). A direction is real when the corrected
  // point is a solution within h / drift_ratio of z: the hyperplane, which misses the traced
  // branch near z, met another family near the stepped point. Its secant from z gives the angle
  // to t.
  std::optional<Chord> own_chord;
  if (!chord_of_j) own_chord.emplace(J, null_cutoff());
  const Chord& chord = chord_of_j ? *chord_of_j : *own_chord;
  const core::VerifyOptions& v = options_.verification;
  const double h = options_.branch_points.probe_step;
  double smallest = std::numeric_limits<double>::infinity();
  int attached = 0;
  Probing probing(z.size());
  report.candidates = candidates;
  report.probed = std::min(candidates, options_.branch_points.max_probes);
  for (int i = 0; i < report.probed; ++i) {
    const core::Vector d = directions.col(i);
    const core::Vector stepped = z + h * d;
    core::Vector y;
    bool by_chord = false;
    if (!probe(chord, d, stepped, probing, y, by_chord)) continue;
    if ((y - z).norm() > h / v.drift_ratio) continue;
    ++attached;
    if (!by_chord && probing.learned < 3) {
      ++probing.learned;
      learn_kinks(y, J, probing.kinks);
    }
    const core::Vector x = y.cwiseProduct(problem_.unit_scale());
    report.attached_points.push_back(x);
    const core::Vector secant = y - z;
    const double cosine = std::min(1.0, std::abs(secant.dot(t)) / secant.norm());
    const double angle = std::acos(cosine) * 180 / std::numbers::pi;
    if (angle < smallest) {
      smallest = angle;
      report.attached_point = x;
    }
  }
  report.attached_dimension = attached;
  report.verified_dimension = attached + 1;
  if (attached == 0) return;
  report.tangent_angle = smallest;
  if (hooks_.describe_branch_point)
    report.attached_description = hooks_.describe_branch_point(report.x, report.attached_point);
}

core::Matrix Locator::directions_beyond(const core::Matrix& J, const core::Vector& t,
                                        BranchPointReport& report, int& candidates) const {
  // Thresholds relative to the branch's Jacobian scale, not to this point's sigma_max: J may
  // vanish at a branch point (x (z - 1) at z = 1), so its own largest singular value is the
  // location error, not a scale.
  core::RankOptions rank_options = options_.rank;
  rank_options.absolute_threshold =
      std::max(rank_options.absolute_threshold, rank_options.relative_threshold * jacobian_scale_);
  const core::RankReport rank = core::rank_report(J, rank_options);
  report.nullity = rank.nullity;
  report.verified_dimension = 0;
  candidates = 0;
  if (rank.nullity < 1) return core::Matrix();
  // The candidate null space with the traced tangent projected out: the directions in which an
  // attached family may leave. (core::verify_null_directions assumes a manifold; at a branch
  // point the solution set is a union of manifolds, so each direction is probed here instead.)
  const core::Matrix& N = rank.null_directions;
  const core::Matrix beyond = N - t * (t.transpose() * N);
  Eigen::JacobiSVD<core::Matrix> svd(beyond, Eigen::ComputeThinU);
  for (Eigen::Index i = 0; i < svd.singularValues().size(); ++i)
    if (svd.singularValues()[i] > 0.5) ++candidates;
  return svd.matrixU();
}

// Each probe first takes chord steps on J with J's columns along the learned kinks
// re-differenced at the stepped point and secant updates (chord_correct: one residual each; d is
// in J's null space, so the hyperplane row is met exactly), then subspace_correct, then, when
// they stall, the loop's corrector (its tolerance and iteration budget, fresh Jacobians; the
// verifier's 60 linear iterations make failed probes the main cost of a branch point, measured
// on the contact bar at 100 intervals). There, stepping 1e-3 off a located point crosses a kink
// of F in every direction: the chord steps alone finish none of 62 probes, each then takes a
// Jacobian (about 20 residuals); with the kink learned at the first probe, 56 of 62 finish in
// 4-9 residuals.
bool Locator::probe(const Chord& chord, const core::Vector& d, const core::Vector& stepped,
                    Probing& probing, core::Vector& y, bool& by_chord) const {
  const core::Vector f = factor();
  y = stepped;
  by_chord = chord_correct(chord, d, stepped, y, &probing.kinks);
  // The subspace stage is skipped once it has failed on at least two of this point's probes
  // and on more than two thirds of them (on the contact bar at 100 intervals it finishes
  // 34 of 62 probes, 2 of 19 at T = 3.2).
  // Nor is it tried when a whole Jacobian costs no more residuals than one differencing along
  // N (a compressed finite-difference Jacobian, core/README.md): the finisher is then as cheap.
  const bool try_subspace =
      !(probing.subspace_failed >= 2 && probing.subspace_failed > 2 * probing.subspace_done) &&
      !(jacobian_residuals_ > 0 && jacobian_residuals_ <= chord.null_space.cols() + 1);
  const bool oks = !by_chord && try_subspace && subspace_correct(chord, d, stepped, y, 4);
  if (!by_chord && try_subspace) ++(oks ? probing.subspace_done : probing.subspace_failed);
  if (!by_chord && !oks) {
    const core::BorderedSystem on_plane(
        problem_,
        {core::BorderRow::hyperplane(d.cwiseProduct(f).normalized(), stepped.cwiseQuotient(f))});
    core::Vector y_local = y.cwiseQuotient(f);
    const core::NewtonSummary s = probe_finisher_->solve(on_plane, y_local);
    if (!s.converged() || !y_local.allFinite()) return false;
    y = y_local.cwiseProduct(f);
  }
  return true;
}

// The probe to y needed fresh Jacobians: J(y) differs from J where the step crossed a kink of
// F. The leading right singular vectors of D = J(y) - J (singular values above 1e-2 of the
// largest, at most three) join the kinks, at most four in all. On the contact bar at 100
// intervals D has one such direction, the same at every probe of a point (the period's column:
// its second singular value is 1e-5..1e-2 of its first, 200..300 against |J| = 1.1e4).
void Locator::learn_kinks(const core::Vector& y, const core::Matrix& J, core::Matrix& kinks) const {
  constexpr Eigen::Index max_kinks = 4;
  core::Matrix Jy;
  if (problem_.jacobian(y.cwiseQuotient(factor()), Jy) != core::EvalStatus::ok) return;
  const core::Matrix D = in_unit_scale(Jy) - J;
  core::Vector sigma;
  core::Matrix directions;
  core::leading_right_singular(D, 3, sigma, directions);
  for (Eigen::Index j = 0; j < sigma.size(); ++j) {
    if (!(sigma(j) > 1e-2 * sigma(0) && sigma(j) > 1e-6 * J.norm())) break;
    if (kinks.cols() >= max_kinks) break;
    core::Vector b = directions.col(j);
    for (int pass = 0; pass < 2; ++pass) b -= kinks * (kinks.transpose() * b);
    if (!(b.norm() > 0.1)) continue;  // already known
    kinks.conservativeResize(Eigen::NoChange, kinks.cols() + 1);
    kinks.col(kinks.cols() - 1) = b.normalized();
  }
}

}  // namespace backbone::continuation::branch_point
