#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "continuation/internal/branch_point_locator.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "core/solvers/bordered_system.hpp"
#include "core/solvers/eigen_newton.hpp"

namespace backbone::continuation::branch_point {

Locator::Locator(const ScaledProblem& problem, ScaledProblem* own,
                 const ContinuationOptions& options, const ContinuationHooks& hooks)
    : problem_(problem), own_(own), options_(options), hooks_(hooks) {
  // What the chord steps leave is finished by Gauss-Newton that keeps its Jacobian while it
  // contracts (core::NewtonOptions::reuse_jacobian), to the verifier's tolerance: a located
  // point's correction within max_iterations 10, a probe's within 8 (on the contact bar the
  // probes that converge take at most 4 iterations of the loop's corrector at 100 intervals,
  // and one of the 49 at T = 3.5 on 200 intervals takes 7 or 8 with the exact Jacobian; 6 left the
  // attached dimension one below the law there).
  core::NewtonOptions newton = options.verification.corrector_options();
  newton.reuse_jacobian = true;
  newton.max_iterations = 10;
  finisher_ = core::make_corrector("eigen", newton);
  newton.max_iterations = 8;
  probe_finisher_ = core::make_corrector("eigen", newton);
}

void Locator::run(Job job, std::vector<BranchPointReport>& found) {
  if (own_) own_->set_units(job.scale, job.residual_factor);
  last_jacobian_ = std::move(job.last_jacobian);
  jacobian_scale_ = job.jacobian_scale;
  found_ = &found;
  locate(job.polyline, job.sign_change);
  found_ = nullptr;
}

double Locator::null_cutoff() const {
  // The rank report's: relative to the branch's Jacobian scale (verify()).
  return options_.rank.relative_threshold * jacobian_scale_;
}

const Chord& Locator::chord_of(const Evaluation& e) const {
  if (!e.chord) e.chord = std::make_shared<const Chord>(e.jacobian, null_cutoff());
  return *e.chord;
}

namespace {

// The hyperplane through polyline at s, orthogonal to the segment that holds s, and the cubic
// Hermite interpolant of that segment's samples and their tangents at s (error O(L^4) in the
// chord length L, where the chord's own is O(L^2)), moved onto the hyperplane.
struct PlaneAt {
  PlaneAt(const std::vector<Sample>& polyline, double s) {
    while (i + 2 < polyline.size() && s > polyline[i + 1].s) ++i;
    const Sample& a = polyline[i];
    const Sample& b = polyline[i + 1];
    const double length = b.s - a.s;
    const double t = length > 0 ? std::clamp((s - a.s) / length, 0.0, 1.0) : 0.0;
    segment = b.z - a.z;
    through = a.z + t * segment;
    normal = segment.normalized();
    const double L = segment.norm();
    const core::Vector ta = a.tangent.dot(segment) < 0 ? core::Vector(-a.tangent) : a.tangent;
    const core::Vector tb = b.tangent.dot(segment) < 0 ? core::Vector(-b.tangent) : b.tangent;
    hermite = (2 * t * t * t - 3 * t * t + 1) * a.z + (t * t * t - 2 * t * t + t) * L * ta +
              (-2 * t * t * t + 3 * t * t) * b.z + (t * t * t - t * t) * L * tb;
    hermite += normal * normal.dot(through - hermite);
    if (!hermite.allFinite() || a.tangent.size() != a.z.size() || b.tangent.size() != b.z.size())
      hermite = through;
  }
  std::size_t i = 0;  // the segment's first sample
  core::Vector segment, through, normal, hermite;
};

}  // namespace

Evaluation Locator::evaluate(const std::vector<Sample>& polyline, double s,
                             const TestFunctionValue& reference, const Chord* initial,
                             const Evaluation* last, const Evaluation* near) {
  Evaluation e;
  const PlaneAt plane(polyline, s);
  const core::Vector& segment = plane.segment;
  const core::Vector& through = plane.through;
  const core::Vector& normal = plane.normal;
  const core::Vector f = factor();
  e.s = s;
  // Start: the cubic Hermite interpolant of the two samples and their tangents.
  e.z = plane.hermite;
  // From a corrected point of the location nearer than the polyline's samples, a tangent
  // predictor onto the hyperplane and chord steps on that point's Jacobian: the bracket shrinks
  // much faster than the polyline's interpolation error does.
  // Else chord steps on the last evaluation's Jacobian (the sample's before the first).
  const Chord* chord = nullptr;
  if (near && near->ok) {
    const double along = normal.dot(near->tangent);
    if (std::abs(along) >= 0.5) {
      e.z = near->z + near->tangent * (normal.dot(through - near->z) / along);
      chord = &chord_of(*near);
    }
  }
  if (!chord) chord = last ? &chord_of(*last) : initial;
  // With an exact Jacobian the chord steps go on past the tolerance while they contract: the
  // period of a located point to round-off (locate()).
  if (!chord ||
      !chord_correct(*chord, normal, through, e.z, nullptr, problem_.base().jacobian_exact())) {
    // From where the chord steps got to, in the loop's units (fresh Jacobians).
    const core::BorderedSystem on_plane(
        problem_, {core::BorderRow::hyperplane(normal.cwiseProduct(f).normalized(),
                                               through.cwiseQuotient(f))});
    core::Vector z = e.z.cwiseQuotient(f);
    if (!finisher_->solve(on_plane, z).converged() || !z.allFinite()) return e;
    e.z = z.cwiseProduct(f);
  }
  // A point on another family is not a point of the branch: it must stay near the chord.
  if ((e.z - through).norm() > 0.25 * segment.norm()) return e;
  core::Matrix J;
  const long residuals_before = problem_.base().counters().residuals;
  if (problem_.jacobian(e.z.cwiseQuotient(f), J) != core::EvalStatus::ok) return e;
  if (problem_.base().counters().residuals > residuals_before)
    jacobian_residuals_ = problem_.base().counters().residuals - residuals_before;
  e.jacobian = in_unit_scale(J);
  if (tangent_from_jacobian(e.jacobian, normal, options_.rank.relative_threshold, e.tangent) !=
      core::EvalStatus::ok)
    return e;
  e.tau = bordered_test_function(e.jacobian, e.tangent, jacobian_scale_, &reference, true);
  e.ok = true;
  return e;
}

// What a location has learned so far: the best point (sampled or evaluated), every corrected
// evaluation (for the next one's start) and every |tau| seen (for the minimisation of |tau|).
struct Locator::Location {
  Location(const std::vector<Sample>& samples, std::shared_ptr<const Chord> last_chord,
           const core::Matrix& last_jacobian);
  // Keeps e (corrected at s), and makes it the best point when its |tau| is the smallest yet.
  void keep(Evaluation& e, double s);
  const Evaluation* last() const { return done.empty() ? nullptr : &done.back(); }
  // The corrected evaluation nearest to s when it is nearer than every sample of the polyline.
  const Evaluation* nearest(double s) const;
  // The test function's value at the known point (sample or evaluation) nearest to s: the
  // reference that orients an evaluation at s (and starts its inverse iteration). Each value is
  // oriented like its reference's, so the values of a chain of continued links share one sign
  // convention, and a sign change between any two of them is a crossing.
  TestFunctionValue tau_near(double s) const;

  const std::vector<Sample>& polyline;
  // Each correction starts with chord steps on the last Jacobian evaluated (Chord): the
  // bracket is short, so it is close; the loop's corrector takes over when they stall. This
  // one is the last sample's (null without it), used until a first evaluation is made.
  std::shared_ptr<const Chord> chord;
  // The best point so far: at first the sampled one with the smallest |tau|.
  core::Vector best_z, best_tangent;
  core::Matrix best_jacobian;               // empty: not kept (a sample before the last)
  std::shared_ptr<const Chord> best_chord;  // of best_jacobian, when a sample's
  int best_done = -1;                       // when an evaluation's: its index in done
  double best_s = 0, best_value = std::numeric_limits<double>::infinity();
  std::vector<Evaluation> done;  // every corrected evaluation, for the next one's start
  // Every value seen, for the minimisation of |tau| (a dip, or a secant iteration whose
  // singular triplet stopped following the reference's).
  std::vector<std::pair<double, double>> seen;  // (s, |tau|)
  int steps = 0;                                // evaluations made
};

Locator::Location::Location(const std::vector<Sample>& samples,
                            std::shared_ptr<const Chord> last_chord,
                            const core::Matrix& last_jacobian)
    : polyline(samples), chord(std::move(last_chord)) {
  for (const Sample& p : polyline)
    if (std::abs(p.tau.value) < std::abs(best_value)) {
      best_z = p.z;
      best_tangent = p.tangent;
      best_s = p.s;
      best_value = p.tau.value;
      const bool last = &p == &polyline.back();
      best_jacobian = last ? last_jacobian : core::Matrix();
      best_chord = last ? chord : nullptr;
    }
  for (const Sample& p : polyline) seen.emplace_back(p.s, std::abs(p.tau.value));
}

void Locator::Location::keep(Evaluation& e, double s) {
  if (std::abs(e.tau.value) < std::abs(best_value)) {
    best_z = e.z;
    best_tangent = e.tangent;
    best_s = s;
    best_value = e.tau.value;
    best_jacobian = e.jacobian;
    best_chord = nullptr;
    best_done = static_cast<int>(done.size());
  }
  done.push_back(e);
}

const Evaluation* Locator::Location::nearest(double s) const {
  double distance = std::numeric_limits<double>::infinity();
  for (const Sample& p : polyline) distance = std::min(distance, std::abs(p.s - s));
  const Evaluation* best = nullptr;
  for (const Evaluation& e : done)
    if (std::abs(e.s - s) < distance) {
      distance = std::abs(e.s - s);
      best = &e;
    }
  return best;
}

TestFunctionValue Locator::Location::tau_near(double s) const {
  if (const Evaluation* e = nearest(s)) return e->tau;
  const Sample* closest = &polyline.front();
  for (const Sample& p : polyline)
    if (std::abs(p.s - s) < std::abs(closest->s - s)) closest = &p;
  return closest->tau;
}

// The secant iteration on the signed test function: its last two values, and whether they
// bracket a root.
struct Locator::Secant {
  bool root_finding = false;  // the iteration runs
  bool bracketed = false;     // f_prev and f_last have opposite signs
  double s_prev = 0, f_prev = 0, s_last = 0, f_last = 0;
};

Evaluation Locator::evaluate_at(Location& at, double s, const TestFunctionValue& reference) {
  Evaluation e = evaluate(at.polyline, s, reference, at.chord.get(), at.last(), at.nearest(s));
  ++at.steps;
  return e;
}

void Locator::locate(const std::vector<Sample>& polyline, bool sign_change) {
  const auto started = std::chrono::steady_clock::now();
  const core::EvaluationCounters& counters = problem_.base().counters();
  const long jacobians_before = counters.jacobians, residuals_before = counters.residuals;
  // The iteration stops when |tau| is 1e-3 of the rank report's relative threshold: J is
  // singular there at the resolution the verification uses, with a margin. With differences,
  // the finite-difference noise of the test function (4e-9..8e-9 at T = 3.6 on 100 intervals)
  // stalls it below that: at 70 intervals, going on costs 6 more evaluations at T = 3.6 and 3.5
  // for nothing. With an exact Jacobian (core::Problem::jacobian_exact) refine_on_branch takes
  // the root to round-off from there: mode 1 at 40 intervals on steps of 0.001 of the amplitude,
  // up to 1e-3 J, puts every period at the law's 2q/p to 1.6e-13 relative. Going on to
  // round-off here instead leaves 9.2e-13 without it, and with it costs 22 % more Jacobians
  // (175 against 144 up to 1.3e-5 J). Near the root a step costs one Jacobian and a few
  // residuals (tangent predictor from the nearest evaluation).
  const double located_value = 1e-3 * options_.rank.relative_threshold;
  BranchPointReport report;
  report.sign_change = sign_change;
  std::shared_ptr<const Chord> chord;
  if (last_jacobian_.size() > 0)
    chord = std::make_shared<const Chord>(last_jacobian_, null_cutoff());
  Location at(polyline, std::move(chord), last_jacobian_);
  Secant secant = start_secant(at, sign_change);
  if (secant.root_finding) secant_steps(at, secant, located_value);
  minimise_modulus(at, located_value);
  refine_on_branch(at);
  verify_best(at, report);
  report.jacobian_evaluations = counters.jacobians - jacobians_before;
  report.residual_evaluations = counters.residuals - residuals_before;
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  found_->push_back(std::move(report));
}

// Secant steps on the signed test function, regula falsi (Illinois: the stale end's value
// halved) once two values of opposite signs bracket the root. A sign change starts bracketed
// by its two samples. A dip starts from its smallest sample and an evaluation at 1 % of the
// way towards its smaller neighbour: near the root tau is linear in s over a short stretch
// only (other singular values take over farther out), so the secant through the two
// extrapolates to it where a fit through the three samples does not (on the contact bar at
// 100 intervals the V through the samples of the dip at T = 3.6 puts it 0.022 off, 4.7 times
// the distance of the smallest sample; the secant through that sample and one 1e-3 away puts
// it 1e-6 off).
Locator::Secant Locator::start_secant(Location& at, bool sign_change) {
  const std::vector<Sample>& polyline = at.polyline;
  Secant secant;
  secant.root_finding = sign_change;
  secant.bracketed = sign_change;
  if (sign_change) {
    secant.s_prev = polyline[0].s;
    secant.f_prev = polyline[0].tau.value;
    secant.s_last = polyline[1].s;
    secant.f_last = polyline[1].tau.value;
  } else if (polyline.size() == 3) {
    const Sample& middle = polyline[1];
    const bool right = std::abs(polyline[2].tau.value) < std::abs(polyline[0].tau.value);
    const double delta = 0.01 * (right ? polyline[2].s - middle.s : polyline[0].s - middle.s);
    const double s = middle.s + delta;
    Evaluation e = evaluate_at(at, s, middle.tau);
    if (e.ok) {
      at.keep(e, s);
      at.seen.emplace_back(s, std::abs(e.tau.value));
      secant.s_prev = middle.s;
      secant.f_prev = middle.tau.value;
      secant.s_last = s;
      secant.f_last = e.tau.value;
      secant.root_finding = e.tau.continued;
      secant.bracketed = secant.f_prev * secant.f_last < 0;
    }
  }
  return secant;
}

// A root brings |tau| down superlinearly; a sign change that is a jump of tau (the
// finite-difference Jacobian across a change of the contact sequence) or a dip that is not a
// root does not: three evaluations in a row that do not halve the smallest |tau| end the
// iteration. When it ends at a root (bracket below location_tolerance, |tau| located, or
// stalled), the values seen are dropped: there is nothing left to minimise.
void Locator::secant_steps(Location& at, Secant& secant, double located_value) {
  const BranchPointOptions& o = options_.branch_points;
  double& s_prev = secant.s_prev;
  double& f_prev = secant.f_prev;
  double& s_last = secant.s_last;
  double& f_last = secant.f_last;
  bool& bracketed = secant.bracketed;
  const double s_min = at.polyline.front().s, s_max = at.polyline.back().s;
  double smallest = std::min(std::abs(f_prev), std::abs(f_last));
  int stale = 0;
  bool left_range = false;
  while (at.steps < o.max_location_steps && std::abs(s_last - s_prev) > o.location_tolerance &&
         stale < 3 && !(std::abs(at.best_value) <= located_value)) {
    double s = (s_prev * f_last - s_last * f_prev) / (f_last - f_prev);
    if (bracketed) {
      const double lo = std::min(s_prev, s_last), hi = std::max(s_prev, s_last);
      if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);
    } else if (!(s > s_min && s < s_max)) {
      left_range = true;
      break;
    }
    Evaluation e = evaluate_at(at, s, at.tau_near(s));
    if (!e.ok) break;
    at.keep(e, s);
    at.seen.emplace_back(s, std::abs(e.tau.value));
    if (std::abs(e.tau.value) < 0.5 * smallest) {
      smallest = std::abs(e.tau.value);
      stale = 0;
    } else {
      ++stale;
    }
    if (!e.tau.continued) break;
    if (e.tau.value == 0) {
      at.seen.clear();
      break;
    }
    if (e.tau.value * f_last < 0) {
      bracketed = true;
      s_prev = s_last;
      f_prev = f_last;
    } else if (bracketed) {
      f_prev *= 0.5;
    } else {
      s_prev = s_last;
      f_prev = f_last;
    }
    s_last = s;
    f_last = e.tau.value;
  }
  if (!left_range && (std::abs(s_last - s_prev) <= o.location_tolerance || stale >= 3 ||
                      std::abs(at.best_value) <= located_value))
    at.seen.clear();
}

// Minimise |tau| from the smallest value seen and its neighbours: |tau| ~ |s - s*| near a
// simple crossing, so fit the V through the three (the steeper side's chord does not straddle
// the kink), golden section when the fit does not shrink the bracket. Stops when the bracket
// is below location_tolerance, or when six evaluations in a row did not halve the smallest
// value (a minimum that does not reach zero: a near miss, reported unverified).
void Locator::minimise_modulus(Location& at, double located_value) {
  const BranchPointOptions& o = options_.branch_points;
  std::vector<std::pair<double, double>>& seen = at.seen;
  std::sort(seen.begin(), seen.end());
  std::size_t middle = 0;
  for (std::size_t i = 1; i < seen.size(); ++i)
    if (seen[i].second < seen[middle].second) middle = i;
  if (!(middle > 0 && middle + 1 < seen.size())) return;
  double sa = seen[middle - 1].first, fa = seen[middle - 1].second;
  double sb = seen[middle].first, fb = seen[middle].second;
  double sc = seen[middle + 1].first, fc = seen[middle + 1].second;
  double previous_width = sc - sa, reference_value = fb;
  int without_progress = 0;
  // A minimum that stays flat above the rank threshold is a jump of the finite-difference test
  // function, not a root: three evaluations in a row that neither halve the smallest value nor
  // exceed twice it end the iteration (on the contact bar at 100 intervals the unverified
  // candidates at T = 3.332 and 3.142 read 1.2e-4..1.5e-4 and 5.5e-4..6.6e-4 at each of their
  // six V-fit evaluations; the verified dip at 3.6 starts 4-5 times above its sampled value).
  // Below the threshold the iteration is at the noise and keeps its six.
  int flat = 0;
  bool golden = false;
  while (at.steps < o.max_location_steps && sc - sa > o.location_tolerance && fb > located_value &&
         without_progress < 6 && flat < 3) {
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
    Evaluation e = evaluate_at(at, s, at.tau_near(s));
    if (!e.ok) break;
    at.keep(e, s);
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
      flat = 0;
    } else {
      ++without_progress;
      flat = f <= 2 * reference_value && reference_value > options_.rank.relative_threshold
                 ? flat + 1
                 : 0;
    }
    const double width = sc - sa;
    golden = width > 0.7 * previous_width;
    previous_width = width;
  }
}

// Near the branch point J is singular along the attached family's directions as well as the
// tangent, so the location's corrections leave a point's component along them at what its start
// had (the loop's corrector tolerance at the samples, a tangent predictor from a point where J
// is nearly singular). Where F is not affine in the unknowns that component moves the test
// function's zero along the branch. Mode 3 of the contact bar at 46 intervals (free knots):
// 2.9e-10 along the attached direction puts the root 1.6e-11 off the law's period 18/23, and
// 4.8e-10 with other steps puts it 2.7e-11 off on the other side. So, with an exact Jacobian,
// the root is found again between two points on either side where |tau| is about 3e-5, each
// corrected on the Jacobian at its start without a rank cut-off: J is not singular there, so
// the component is the branch's to round-off. Secant steps then evaluate the test function at
// points corrected from the two's cubic Hermite interpolant on the last point's Jacobian with
// the near-null directions dropped, which leaves that component at the interpolant's. The same
// runs put 18/23 at the law's period to 7e-15 whatever the steps (0.05 to 0.002); mode 1 at 40
// to 200 intervals on steps of 0.05, 0.02 and 0.005, every verified branch point up to 3e-5 J
// (128) at 2q/p to 6.1e-13 relative and of the law's dimension (or below it where fewer
// directions were probed than there are candidates).
void Locator::refine_on_branch(Location& at) {
  // |tau| at the two points; a location that did not bring |tau| far below it found no root.
  // Farther out the interpolant spans kinks of the branch: ends at 1e-4 put T = 3.5 3e-12 off
  // at 100 and 140 intervals, at 1e-3 4e-9.
  const double end_value = 3e-5;
  if (!problem_.base().jacobian_exact() || at.best_done < 0 ||
      !(std::abs(at.best_value) <= 1e-3 * end_value))
    return;
  const BranchPointOptions& o = options_.branch_points;
  const Evaluation& best = at.done[static_cast<std::size_t>(at.best_done)];
  // |tau| ~ slope |s - s*|: the slope from the known value nearest the root that is well above
  // round-off.
  double slope = 0, distance = std::numeric_limits<double>::infinity();
  const auto consider = [&](double s, double value) {
    const double d = std::abs(s - at.best_s);
    if (std::abs(value) >= 1e-9 && d > 0 && d < distance) {
      distance = d;
      slope = std::abs(value) / d;
    }
  };
  for (const Sample& p : at.polyline) consider(p.s, p.tau.value);
  for (const Evaluation& e : at.done) consider(e.s, e.tau.value);
  if (!(slope > 0)) return;
  const double delta = end_value / slope;
  const double s_a = std::max(at.best_s - delta, at.polyline.front().s);
  const double s_b = std::min(at.best_s + delta, at.polyline.back().s);
  if (!(s_b - s_a > o.location_tolerance)) return;
  // Each from the located point along its tangent onto its hyperplane; its tangent to
  // round-off (the interpolant's).
  std::vector<Sample> ends(2);
  core::Matrix J_a, J_b;
  const auto end = [&](double s, Sample& out, core::Matrix& J) {
    const PlaneAt plane(at.polyline, s);
    const double along = plane.normal.dot(best.tangent);
    if (!(std::abs(along) >= 0.5)) return false;
    out.s = s;
    return correct_on_plane(
               plane.normal, plane.through,
               best.z + best.tangent * (plane.normal.dot(plane.through - best.z) / along), 0.0,
               nullptr, out.z, J) &&
           tangent_from_jacobian(J, plane.normal, 0.0, out.tangent) == core::EvalStatus::ok;
  };
  if (!end(s_a, ends[0], J_a) || !end(s_b, ends[1], J_b)) return;
  at.steps += 2;
  // The test function's border here is the chord of the two, not each point's tangent: where
  // J's second-smallest singular value is below the rank threshold the tangent is the normal's
  // component in a two-dimensional null space, so it turns there, and with it the singular
  // vectors that orient the values. The chord is the branch's tangent to O(delta^2), and the
  // bordered matrix is singular where J loses rank whatever the border.
  const core::Vector border = (ends[1].z - ends[0].z).normalized();
  ends[0].tau = bordered_test_function(J_a, border, jacobian_scale_, nullptr, false);
  ends[1].tau = bordered_test_function(J_b, border, jacobian_scale_, &ends[0].tau, true);
  if (!ends[1].tau.continued || !(ends[0].tau.value * ends[1].tau.value < 0)) return;
  double s_prev = s_a, f_prev = ends[0].tau.value, s_last = s_b, f_last = ends[1].tau.value;
  std::vector<Evaluation> found;
  double smallest = std::min(std::abs(f_prev), std::abs(f_last));
  // A root: |tau| at most 1e-12 (3e-8 of the ends'), a period to 1e-12 where tau grows like T
  // or faster (on the contact bar it grows like 1..20 T).
  const double root_value = 1e-12;
  int stale = 0;
  while (found.size() < 8 && std::abs(s_last - s_prev) > 1e-3 * o.location_tolerance && stale < 2) {
    double s = (s_prev * f_last - s_last * f_prev) / (f_last - f_prev);
    const double lo = std::min(s_prev, s_last), hi = std::max(s_prev, s_last);
    if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);
    // From the interpolant, chord steps with the near-null directions dropped: they leave the
    // point's component along them at the interpolant's.
    const PlaneAt plane(ends, s);
    Evaluation e;
    ++at.steps;
    const core::Matrix& chord = found.empty() ? best.jacobian : found.back().jacobian;
    if (!correct_on_plane(plane.normal, plane.through, plane.hermite,
                          options_.rank.relative_threshold, &chord, e.z, e.jacobian))
      break;
    e.ok = true;
    e.s = s;
    e.tau = bordered_test_function(e.jacobian, border, jacobian_scale_, &ends[0].tau, true);
    if (!e.tau.continued) {
      // At the root the left vector is the round-off's: a value far below every other is it.
      if (std::abs(e.tau.value) <= root_value) found.push_back(e);
      break;
    }
    found.push_back(e);
    if (std::abs(e.tau.value) < 0.5 * smallest) {
      smallest = std::abs(e.tau.value);
      stale = 0;
    } else {
      ++stale;
    }
    if (std::abs(e.tau.value) <= 1e-2 * root_value) break;
    if (e.tau.value * f_last < 0) {
      s_prev = s_last;
      f_prev = f_last;
    } else {
      f_prev *= 0.5;
    }
    s_last = s;
    f_last = e.tau.value;
  }
  std::size_t root = 0;
  for (std::size_t k = 1; k < found.size(); ++k)
    if (std::abs(found[k].tau.value) < std::abs(found[root].tau.value)) root = k;
  if (found.empty() || !(std::abs(found[root].tau.value) <= root_value)) return;
  Evaluation& e = found[root];
  // The root's tangent, for the verification (the hyperplanes here are all orthogonal to the
  // chord of the ends).
  if (tangent_from_jacobian(e.jacobian, border, options_.rank.relative_threshold, e.tangent) !=
      core::EvalStatus::ok)
    return;
  at.best_z = e.z;
  at.best_tangent = e.tangent;
  at.best_s = e.s;
  at.best_value = e.tau.value;
  at.best_jacobian = e.jacobian;
  at.best_chord = nullptr;
  at.best_done = static_cast<int>(at.done.size());
  at.done.push_back(e);
}

bool Locator::correct_on_plane(const core::Vector& normal, const core::Vector& through,
                               core::Vector y, double cutoff, const core::Matrix* chord,
                               core::Vector& z, core::Matrix& J_out) const {
  const core::Vector f = factor();
  const core::Vector& rf = problem_.residual_factor();
  const double tolerance = options_.verification.corrector_options().residual_tolerance;
  const auto jacobian_at = [&](const core::Vector& at, core::Matrix& J) {
    if (problem_.jacobian(at.cwiseQuotient(f), J) != core::EvalStatus::ok) return false;
    J = in_unit_scale(J);
    return J.allFinite();
  };
  // The steps' matrix, [J; normal^T], J the chord's or the start's, factorised once.
  core::Matrix bordered;
  {
    core::Matrix J;
    if (chord) {
      J = *chord;
    } else if (!jacobian_at(y, J)) {
      return false;
    }
    bordered.resize(J.rows() + 1, J.cols());
    bordered.topRows(J.rows()) = J;
    bordered.row(J.rows()) = normal.transpose();
  }
  Eigen::CompleteOrthogonalDecomposition<core::Matrix> cod;
  if (cutoff > 0) cod.setThreshold(cutoff);  // relative to the largest pivot
  cod.compute(bordered);
  // Past the tolerance, the steps go on while each halves |F|: they converge linearly (a chord,
  // or a Jacobian from across a kink of a piecewise affine F: mode 1 of the contact bar at 40
  // intervals next to T = 3.2, |F| falls 2.6-fold a step from 1.8e-10, where stopping at the
  // tolerance leaves T 9e-13 off the law's). The iterate with the smallest |F|.
  core::Vector best_y;
  double best_norm = std::numeric_limits<double>::infinity();
  bool converged = false;
  for (int iteration = 0; iteration < 16; ++iteration) {
    core::Vector r;
    if (problem_.residual(y.cwiseQuotient(f), r) != core::EvalStatus::ok || !r.allFinite()) break;
    const double plane = normal.dot(y - through);
    const bool within = r.lpNorm<Eigen::Infinity>() <= tolerance && std::abs(plane) <= tolerance;
    if (rf.size() > 0) r = r.cwiseProduct(rf);
    const double norm = std::hypot(r.norm(), plane);
    if (converged && !(norm <= 0.5 * best_norm)) break;
    if (norm < best_norm) {
      best_y = y;
      best_norm = norm;
    }
    converged = converged || within;
    core::Vector rhs(r.size() + 1);
    rhs << -r, -plane;
    const core::Vector dx = cod.solve(rhs);
    if (!dx.allFinite()) break;
    y += dx;
  }
  if (!converged) return false;
  z = std::move(best_y);
  return jacobian_at(z, J_out);
}

// The report's location (the best point, the sample it follows) and its verification there.
void Locator::verify_best(Location& at, BranchPointReport& report) {
  const std::vector<Sample>& polyline = at.polyline;
  report.location_steps = at.steps;
  report.test_value = at.best_value;
  report.arclength = at.best_s;
  report.after_point = polyline.front().index;
  for (const Sample& p : polyline)
    if (p.s <= at.best_s) report.after_point = p.index;
  if (report.after_point == polyline.back().index && polyline.size() > 1)
    report.after_point = polyline[polyline.size() - 2].index;
  if (at.best_done >= 0) at.best_chord = at.done[static_cast<std::size_t>(at.best_done)].chord;
  verify(report, at.best_z, at.best_tangent, at.best_jacobian, at.best_chord.get());
}

}  // namespace backbone::continuation::branch_point
