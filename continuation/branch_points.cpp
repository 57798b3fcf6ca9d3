#include "continuation/branch_points.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "continuation/pseudo_arclength.hpp"
#include "core/bordered_system.hpp"

namespace backbone::continuation {

TestFunctionValue bordered_test_function(const core::Matrix& J, const core::Vector& tangent,
                                         double scale, const TestFunctionValue* reference) {
  const Eigen::Index m = J.rows(), n = J.cols();
  TestFunctionValue result;
  core::Matrix bordered(m + 1, n);
  bordered.topRows(m) = scale > 0 ? core::Matrix(J / scale) : J;
  bordered.row(m) = tangent.normalized().transpose();
  Eigen::BDCSVD<core::Matrix> svd(bordered, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::Index last = svd.singularValues().size() - 1;
  result.left = svd.matrixU().col(last);
  result.right = svd.matrixV().col(last);
  result.value = svd.singularValues()[last];
  if (reference && reference->right.size() == result.right.size() &&
      reference->left.size() == result.left.size()) {
    // Follow the smallest singular triplet: orient both vectors like the reference's, then
    // u . (A v) = +-sigma is the signed, continuous value (analytic SVD). When the triplet was
    // replaced by another one (a crossing of singular values), the sign means nothing.
    const double dv = result.right.dot(reference->right);
    const double du = result.left.dot(reference->left);
    result.continued = std::abs(dv) >= 0.5 && std::abs(du) >= 0.5;
    if (dv < 0) result.right = -result.right;
    if (du < 0) result.left = -result.left;
    result.value = result.left.dot(bordered * result.right);
  }
  return result;
}

struct BranchPointDetector::Evaluation {
  bool ok = false;
  core::Vector z, tangent;
  TestFunctionValue tau;
};

BranchPointDetector::BranchPointDetector(const ScaledProblem& problem,
                                         const ContinuationOptions& options,
                                         const ContinuationHooks& hooks, core::Corrector& corrector)
    : problem_(problem), options_(options), hooks_(hooks), corrector_(corrector) {}

BranchPointDetector::~BranchPointDetector() = default;

double BranchPointDetector::last_value() const {
  return samples_.empty() ? std::numeric_limits<double>::quiet_NaN() : samples_.back().tau.value;
}

void BranchPointDetector::restore(std::vector<TestFunctionSample> samples, double jacobian_scale) {
  samples_ = std::move(samples);
  jacobian_scale_ = jacobian_scale;
}

std::vector<BranchPointReport> BranchPointDetector::take() {
  std::vector<BranchPointReport> out = std::move(found_);
  found_.clear();
  return out;
}

void BranchPointDetector::add(int index, const core::Vector& z, const core::Vector& tangent,
                              const core::Matrix& J, double arclength) {
  Sample sample;
  sample.index = index;
  sample.z = z;
  sample.tangent = tangent;
  sample.s = arclength;
  // One scale for the whole branch (J may vanish at a branch point: a per-point norm would hide
  // it): the Frobenius norm of the first point's Jacobian.
  if (!(jacobian_scale_ > 0)) jacobian_scale_ = J.norm() > 0 ? J.norm() : 1.0;
  sample.tau = bordered_test_function(J, tangent, jacobian_scale_,
                                      samples_.empty() ? nullptr : &samples_.back().tau);
  samples_.push_back(std::move(sample));
  if (samples_.size() > 3) samples_.erase(samples_.begin());
  const std::size_t k = samples_.size();
  if (k >= 2) {
    const Sample& a = samples_[k - 2];
    const Sample& b = samples_[k - 1];
    if (b.tau.continued && a.tau.value * b.tau.value < 0) {
      locate({a, b}, true);
      samples_.erase(samples_.begin(), samples_.end() - 1);
      return;
    }
  }
  if (k == 3) {
    const double fa = std::abs(samples_[0].tau.value), fb = std::abs(samples_[1].tau.value),
                 fc = std::abs(samples_[2].tau.value);
    if (fb < options_.branch_points.dip_ratio * std::min(fa, fc)) {
      locate(samples_, false);
      samples_.erase(samples_.begin(), samples_.end() - 1);
    }
  }
}

BranchPointDetector::Evaluation BranchPointDetector::evaluate(const std::vector<Sample>& polyline,
                                                              double s,
                                                              const TestFunctionValue& reference) {
  Evaluation e;
  std::size_t i = 0;
  while (i + 2 < polyline.size() && s > polyline[i + 1].s) ++i;
  const Sample& a = polyline[i];
  const Sample& b = polyline[i + 1];
  const double length = b.s - a.s;
  const double fraction = length > 0 ? std::clamp((s - a.s) / length, 0.0, 1.0) : 0.0;
  const core::Vector chord = b.z - a.z;
  const core::Vector through = a.z + fraction * chord;
  const core::Vector normal = chord.normalized();
  const core::BorderedSystem on_plane(problem_, {core::BorderRow::hyperplane(normal, through)});
  e.z = through;
  if (!corrector_.solve(on_plane, e.z).converged() || !e.z.allFinite()) return e;
  // A point on another family is not a point of the branch: it must stay near the chord.
  if ((e.z - through).norm() > 0.25 * chord.norm()) return e;
  core::Matrix J;
  if (problem_.jacobian(e.z, J) != core::EvalStatus::ok) return e;
  if (tangent_from_jacobian(J, normal, options_.rank.relative_threshold, e.tangent) !=
      core::EvalStatus::ok)
    return e;
  e.tau = bordered_test_function(J, e.tangent, jacobian_scale_, &reference);
  e.ok = true;
  return e;
}

void BranchPointDetector::locate(const std::vector<Sample>& polyline, bool sign_change) {
  const auto started = std::chrono::steady_clock::now();
  const BranchPointOptions& o = options_.branch_points;
  const TestFunctionValue& reference = polyline.front().tau;
  BranchPointReport report;
  report.sign_change = sign_change;
  // The best point so far: the sampled one with the smallest |tau|.
  core::Vector best_z, best_tangent;
  double best_s = 0, best_value = std::numeric_limits<double>::infinity();
  for (const Sample& p : polyline)
    if (std::abs(p.tau.value) < std::abs(best_value)) {
      best_z = p.z;
      best_tangent = p.tangent;
      best_s = p.s;
      best_value = p.tau.value;
    }
  const auto keep = [&](const Evaluation& e, double s) {
    if (std::abs(e.tau.value) < std::abs(best_value)) {
      best_z = e.z;
      best_tangent = e.tangent;
      best_s = s;
      best_value = e.tau.value;
    }
  };
  // Every value seen, for the minimisation of |tau| (a dip, or a secant iteration whose
  // singular triplet stopped following the reference's).
  std::vector<std::pair<double, double>> seen;  // (s, |tau|)
  for (const Sample& p : polyline) seen.emplace_back(p.s, std::abs(p.tau.value));
  int steps = 0;
  if (sign_change) {
    // Illinois: regula falsi with the stale end's value halved.
    double sa = polyline[0].s, fa = polyline[0].tau.value;
    double sb = polyline[1].s, fb = polyline[1].tau.value;
    while (steps < o.max_location_steps && std::abs(sb - sa) > o.location_tolerance) {
      double s = (sa * fb - sb * fa) / (fb - fa);
      const double lo = std::min(sa, sb), hi = std::max(sa, sb);
      if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);
      const Evaluation e = evaluate(polyline, s, reference);
      ++steps;
      if (!e.ok) break;
      keep(e, s);
      seen.emplace_back(s, std::abs(e.tau.value));
      if (!e.tau.continued) break;
      if (e.tau.value == 0) {
        seen.clear();
        break;
      }
      if (e.tau.value * fb < 0) {
        sa = sb;
        fa = fb;
      } else {
        fa *= 0.5;
      }
      sb = s;
      fb = e.tau.value;
    }
    if (std::abs(sb - sa) <= o.location_tolerance) seen.clear();
  }
  // Minimise |tau| from the smallest value seen and its neighbours: |tau| ~ |s - s*| near a
  // simple crossing, so fit the V through the three (the steeper side's chord does not straddle
  // the kink), golden section when the fit does not shrink the bracket. Stops when the bracket
  // is below location_tolerance, or when six evaluations in a row did not halve the smallest
  // value (a minimum that does not reach zero: a near miss, reported unverified).
  std::sort(seen.begin(), seen.end());
  std::size_t middle = 0;
  for (std::size_t i = 1; i < seen.size(); ++i)
    if (seen[i].second < seen[middle].second) middle = i;
  if (middle > 0 && middle + 1 < seen.size()) {
    double sa = seen[middle - 1].first, fa = seen[middle - 1].second;
    double sb = seen[middle].first, fb = seen[middle].second;
    double sc = seen[middle + 1].first, fc = seen[middle + 1].second;
    double previous_width = sc - sa, reference_value = fb;
    int without_progress = 0;
    bool golden = false;
    while (steps < o.max_location_steps && sc - sa > o.location_tolerance && fb > 0 &&
           without_progress < 6) {
      double s;
      const bool right_larger = sc - sb > sb - sa;
      if (golden) {
        s = right_larger ? sb + 0.381966 * (sc - sb) : sb - 0.381966 * (sb - sa);
      } else {
        const double m1 = (fa - fb) / (sb - sa), m2 = (fc - fb) / (sc - sb);
        s = m1 >= m2 ? sc - fc / m1 : sa + fa / m2;
        const double nudge = 0.25 * o.location_tolerance;
        if (std::abs(s - sb) < nudge) s = right_larger ? sb + nudge : sb - nudge;
        if (!(s > sa && s < sc)) s = right_larger ? 0.5 * (sb + sc) : 0.5 * (sa + sb);
      }
      const Evaluation e = evaluate(polyline, s, reference);
      ++steps;
      if (!e.ok) break;
      keep(e, s);
      const double f = std::abs(e.tau.value);
      if (f < fb) {
        if (s < sb) {
          sc = sb;
          fc = fb;
        } else {
          sa = sb;
          fa = fb;
        }
        sb = s;
        fb = f;
      } else if (s < sb) {
        sa = s;
        fa = f;
      } else {
        sc = s;
        fc = f;
      }
      if (fb < 0.5 * reference_value) {
        reference_value = fb;
        without_progress = 0;
      } else {
        ++without_progress;
      }
      const double width = sc - sa;
      golden = width > 0.7 * previous_width;
      previous_width = width;
    }
  }
  report.location_steps = steps;
  report.test_value = best_value;
  report.arclength = best_s;
  report.after_point = polyline.front().index;
  for (const Sample& p : polyline)
    if (p.s <= best_s) report.after_point = p.index;
  if (report.after_point == polyline.back().index && polyline.size() > 1)
    report.after_point = polyline[polyline.size() - 2].index;
  verify(report, best_z, best_tangent);
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  found_.push_back(std::move(report));
}

void BranchPointDetector::verify(BranchPointReport& report, const core::Vector& z,
                                 const core::Vector& tangent) {
  report.x = problem_.to_unknowns(z);
  report.observables = problem_.observables(z);
  report.tangent_angle = std::numeric_limits<double>::quiet_NaN();
  core::Matrix J;
  if (problem_.jacobian(z, J) != core::EvalStatus::ok) return;
  // Thresholds relative to the branch's Jacobian scale, not to this point's sigma_max: J may
  // vanish at a branch point (x (z - 1) at z = 1), so its own largest singular value is the
  // location error, not a scale.
  core::RankOptions rank_options = options_.rank;
  rank_options.absolute_threshold =
      std::max(rank_options.absolute_threshold, rank_options.relative_threshold * jacobian_scale_);
  const core::RankReport rank = core::rank_report(J, rank_options);
  report.nullity = rank.nullity;
  report.verified_dimension = 0;
  if (rank.nullity < 1) return;
  // The candidate null space with the traced tangent projected out: the directions in which an
  // attached family may leave. (core::verify_null_directions assumes a manifold; at a branch
  // point the solution set is a union of manifolds, so each direction is probed here instead.)
  const core::Vector t = tangent.normalized();
  const core::Matrix& N = rank.null_directions;
  const core::Matrix beyond = N - t * (t.transpose() * N);
  Eigen::JacobiSVD<core::Matrix> svd(beyond, Eigen::ComputeThinU);
  int candidates = 0;
  for (Eigen::Index i = 0; i < svd.singularValues().size(); ++i)
    if (svd.singularValues()[i] > 0.5) ++candidates;
  // One probe per candidate direction d: step by h along d and re-correct on the hyperplane
  // through the stepped point orthogonal to d (the loop's corrector). A direction is real when the
  // corrected point is a solution within h / drift_ratio of z: the hyperplane, which misses the
  // traced branch near z, met another family near the stepped point. Its secant from z gives the
  // angle to t.
  const core::VerifyOptions& v = options_.verification;
  const double h = v.step;
  double smallest = std::numeric_limits<double>::infinity();
  int attached = 0;
  for (int i = 0; i < std::min(candidates, options_.branch_points.max_probes); ++i) {
    const core::Vector d = svd.matrixU().col(i);
    const core::Vector stepped = z + h * d;
    const core::BorderedSystem on_plane(problem_, {core::BorderRow::hyperplane(d, stepped)});
    core::Vector y = stepped;
    // The loop's corrector, tolerance and iteration budget: a probe converges like a step of
    // the branch (the verifier's 60 linear iterations made failed probes the main cost of a
    // branch point, measured on the contact bar at 100 intervals).
    const core::NewtonSummary s = corrector_.solve(on_plane, y);
    if (!s.converged() || !y.allFinite() || (y - z).norm() > h / v.drift_ratio) continue;
    ++attached;
    report.attached_points.push_back(problem_.to_unknowns(y));
    const core::Vector secant = y - z;
    const double cosine = std::min(1.0, std::abs(secant.dot(t)) / secant.norm());
    const double angle = std::acos(cosine) * 180 / std::numbers::pi;
    if (angle < smallest) {
      smallest = angle;
      report.attached_point = problem_.to_unknowns(y);
    }
  }
  report.attached_dimension = attached;
  report.verified_dimension = attached + 1;
  if (attached == 0) return;
  report.tangent_angle = smallest;
  if (hooks_.describe_branch_point)
    report.attached_description = hooks_.describe_branch_point(report.x, report.attached_point);
}

}  // namespace backbone::continuation
