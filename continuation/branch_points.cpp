#include "continuation/branch_points.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <thread>

#include "continuation/pseudo_arclength.hpp"
#include "core/bordered_system.hpp"
#include "core/eigen_newton.hpp"
#include "core/few_singular_values.hpp"
#include "core/job_queue.hpp"

namespace backbone::continuation {

namespace {

// Forward-difference step for J's columns along unit directions at y (scaled unknowns): the
// square root of the machine epsilon, relative to y's largest entry once that exceeds 1.
double difference_step(const core::Vector& y) {
  return 1.5e-8 * std::max(1.0, y.lpNorm<Eigen::Infinity>());
}

}  // namespace

TestFunctionValue bordered_test_function(const core::Matrix& J, const core::Vector& tangent,
                                         double scale, const TestFunctionValue* reference,
                                         bool iterate) {
  const Eigen::Index m = J.rows(), n = J.cols();
  TestFunctionValue result;
  core::Matrix bordered(m + 1, n);
  bordered.topRows(m) = scale > 0 ? core::Matrix(J / scale) : J;
  bordered.row(m) = tangent.normalized().transpose();
  const core::Vector start = reference ? reference->right : core::Vector();
  if (!iterate ||
      !core::smallest_singular_triplet(bordered, start, result.left, result.right, result.value)) {
    Eigen::BDCSVD<core::Matrix> svd(bordered, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::Index last = svd.singularValues().size() - 1;
    result.left = svd.matrixU().col(last);
    result.right = svd.matrixV().col(last);
    result.value = svd.singularValues()[last];
  }
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

// Chord corrections with one Jacobian J (the unit scale's, m x n): Gauss-Newton steps with J's
// rank-truncated least-squares solution of least norm, and, for the hyperplane row
// a . (y - anchor) = 0, a move in J's null space N towards a. The constraint is met after every
// step when a has a component in N (|N^T a| >= 1/2): a probe direction is one of N's, and a chord
// of the branch is close to its tangent, which is in N. One residual per step.
// The rank is revealed by a complete orthogonal decomposition (column-pivoted QR, then a QR of
// the kept rows: J P = Q [T 0; 0 0] Z), pivots below cutoff counting as zero: 0.34 ms for the
// 200 x 101 Jacobian of the contact bar at 100 intervals where the thin SVD took 6 ms.
struct BranchPointDetector::Chord {
  core::Matrix jacobian;  // J itself
  Eigen::CompleteOrthogonalDecomposition<core::Matrix> cod;
  core::Matrix null_space;  // n x nullity, orthonormal
  Chord(const core::Matrix& J, double cutoff) : jacobian(J) {
    const Eigen::Index n = J.cols();
    // The first pivot of the column-pivoted QR is the largest column norm.
    const double largest = J.size() > 0 ? J.colwise().norm().maxCoeff() : 0.0;
    if (largest > 0) cod.setThreshold(std::min(1.0, cutoff / largest));
    cod.compute(J);
    const Eigen::Index rank = cod.rank();
    const core::Matrix Z = cod.matrixZ();
    null_space = cod.colsPermutation() * Z.bottomRows(n - rank).transpose();
  }
  // The least-squares solution of least norm of J x = b (b: m x k).
  core::Matrix solve(const core::Matrix& b) const { return cod.solve(b); }
};

struct BranchPointDetector::Evaluation {
  bool ok = false;
  double s = 0;             // where on the bracket's polyline
  core::Vector z, tangent;  // unit scale
  core::Matrix jacobian;    // unit scale, at z
  TestFunctionValue tau;
  // The chord of `jacobian` (its SVD), made on first use (chord_of): by the next evaluation's
  // start and, at the best one, by the verification, which share it.
  mutable std::shared_ptr<const Chord> chord;
};

namespace {

// J in units of factor (relative to the unit scale) and residual factor rf, in the unit scale:
// diag(rf) J diag(1 ./ factor).
core::Matrix jacobian_in_unit_scale(const core::Matrix& J, const core::Vector& factor,
                                    const core::Vector& rf) {
  core::Matrix out = J * factor.cwiseInverse().asDiagonal();
  if (rf.size() > 0) out = rf.asDiagonal() * out;
  return out;
}

}  // namespace

// What a location needs of the detector, copied when the candidate is bracketed: the loop goes
// on (and its units change) while the worker locates it.
struct BranchPointDetector::Job {
  std::vector<Sample> polyline;
  bool sign_change = false;
  core::Matrix last_jacobian;  // the last sample's, unit scale
  double jacobian_scale = 0;
  core::Vector scale, residual_factor;  // the loop's units then (ScaledProblem::set_units)
};

// Locates a bracketed candidate and verifies it (the header's 'Detection, location,
// verification'). One per detector, on the loop's thread or on the worker's, which runs the jobs
// in the order they were bracketed: what it learns from one candidate to the next (the
// residuals a Jacobian took) comes in the same order either way, so the rows are the same bits.
class BranchPointDetector::Locator {
 public:
  // problem: the view the candidates are corrected in; own: the same view when the locator sets
  // its units job by job (the worker's copy of the problem), null on the loop's thread (the
  // loop's view already has the job's units).
  Locator(const ScaledProblem& problem, ScaledProblem* own, const ContinuationOptions& options,
          const ContinuationHooks& hooks);
  // Locates and verifies the job's candidate; appends its report (when one is made) to found.
  void run(Job job, std::vector<BranchPointReport>& found);

 private:
  // The view's units relative to the unit scale (ScaledProblem::scale() ./ unit_scale()).
  core::Vector factor() const { return problem_.scale().cwiseQuotient(problem_.unit_scale()); }
  core::Matrix in_unit_scale(const core::Matrix& J) const {
    return jacobian_in_unit_scale(J, factor(), problem_.residual_factor());
  }
  // Singular values at most this count as zero (the rank report's threshold, verify()).
  double null_cutoff() const;
  // Chord steps (one residual each) onto F = 0 and normal . (y - anchor) = 0, unit scale, with
  // secant (good Broyden) updates of the chord's J; kinks (n x q, orthonormal): directions along
  // which J is re-differenced at the start (q residuals). False when they do not converge to the
  // verifier's corrector tolerance.
  bool chord_correct(const Chord& chord, const core::Vector& normal, const core::Vector& anchor,
                     core::Vector& y, const core::Matrix* kinks = nullptr) const;
  // Gauss-Newton on J with its columns along J's null space N re-differenced at an iterate
  // (N.cols() residuals instead of a Jacobian's n), kept while its steps halve |F| (one residual
  // each), onto the same constraints; at most max_differences differencings.
  bool subspace_correct(const Chord& chord, const core::Vector& normal, const core::Vector& anchor,
                        core::Vector& y, int max_differences) const;
  // The point on the hyperplane through the bracket's polyline at s, orthogonal to it, and its
  // test function. Starts from near (a corrected evaluation nearer than the samples: tangent
  // predictor, chord steps on its Jacobian) or else from the samples' cubic Hermite interpolant
  // (chord steps on the last evaluation's Jacobian, or on initial before the first).
  // initial: the chord of the last sample's Jacobian, used until a first evaluation (last) is
  // made.
  Evaluation evaluate(const std::vector<Sample>& polyline, double s, const TestFunctionValue& ref,
                      const Chord* initial, const Evaluation* last, const Evaluation* near);
  // The chord of e's Jacobian, made on first use.
  const Chord& chord_of(const Evaluation& e) const;
  void locate(const std::vector<Sample>& polyline, bool sign_change);
  // chord_of_j: J's Chord when the location made it (nullptr: made here).
  void verify(BranchPointReport& report, const core::Vector& z, const core::Vector& tangent,
              core::Matrix J, const Chord* chord_of_j = nullptr);

  const ScaledProblem& problem_;
  ScaledProblem* own_;
  const ContinuationOptions& options_;
  const ContinuationHooks& hooks_;
  double jacobian_scale_ = 0;
  core::Matrix last_jacobian_;
  long jacobian_residuals_ = 0;  // residuals the last Jacobian evaluate() computed took (0: none)
  std::unique_ptr<core::Corrector> finisher_, probe_finisher_;  // after chord steps stall
  std::vector<BranchPointReport>* found_ = nullptr;             // run()'s
};

const BranchPointDetector::Chord& BranchPointDetector::Locator::chord_of(
    const Evaluation& e) const {
  if (!e.chord) e.chord = std::make_shared<const Chord>(e.jacobian, null_cutoff());
  return *e.chord;
}

bool BranchPointDetector::Locator::chord_correct(const Chord& chord, const core::Vector& normal,
                                                 const core::Vector& anchor, core::Vector& y,
                                                 const core::Matrix* kinks) const {
  const core::Matrix& J = chord.jacobian;
  const core::Matrix& N = chord.null_space;
  const core::Vector w = N.transpose() * normal;
  if (!(w.squaredNorm() >= 0.25)) return false;
  const core::Vector f = factor();
  const core::Vector& rf = problem_.residual_factor();
  const double tolerance = options_.verification.corrector_options().residual_tolerance;
  const Eigen::Index m = J.rows(), n = J.cols(), k = N.cols();
  // Secant updates of the chord matrix, B = J + A C^T (good Broyden, unit columns of C): the
  // contact bar's residual is piecewise affine in u0, and where a step crosses into another
  // piece its Jacobian differs from J by rank one (measured at the branch points of the contact
  // bar at 100 intervals: the difference's second singular value is 1e-3..1e-5 of its first),
  // so one update turns the chord into the piece's own matrix. PA = P A and RA = (I - J P) A,
  // the part of A outside J's range, are kept with them.
  constexpr int max_updates = 6;
  core::Matrix A(m, 0), C(n, 0), PA(n, 0), RA(m, 0);
  const double row_scale = 1.0 / std::max(J.norm(), std::numeric_limits<double>::min());
  // On failure y is left at the iterate with the smallest residual (a start for a corrector).
  core::Vector best = y;
  double best_norm = std::numeric_limits<double>::infinity();
  int without_progress = 0;
  core::Vector r_previous, dx;
  for (int iteration = 0; iteration < 30; ++iteration) {
    core::Vector r;
    if (problem_.residual(y.cwiseQuotient(f), r) != core::EvalStatus::ok) break;
    const double plane = normal.dot(y - anchor);
    if (r.lpNorm<Eigen::Infinity>() <= tolerance && std::abs(plane) <= tolerance) return true;
    if (rf.size() > 0) r = r.cwiseProduct(rf);
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
      // J's columns along the kink directions, differenced at the start (one residual each).
      const double h = difference_step(y);
      const Eigen::Index q = kinks->cols();
      A.resize(m, q);
      for (Eigen::Index i = 0; i < q; ++i) {
        core::Vector ri;
        if (problem_.residual((y + h * kinks->col(i)).cwiseQuotient(f), ri) != core::EvalStatus::ok)
          return false;
        if (rf.size() > 0) ri = ri.cwiseProduct(rf);
        A.col(i) = (ri - r) / h - J * kinks->col(i);
      }
      C = *kinks;
      PA = chord.solve(A);
      RA = A - J * PA;
    } else if (iteration > 0 && A.cols() < max_updates) {
      const double length = dx.norm();
      if (length > 0) {
        const core::Vector c = dx / length;
        const core::Vector Bc = J * c + A * (C.transpose() * c);
        const core::Vector a = (r - r_previous) / length - Bc;
        if (a.norm() > 1e-12 * (r - r_previous).norm() / length) {
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
      }
    }
    // The step dx = -P (r + A theta) + N c with theta = C^T dx and normal . dx = -plane; the
    // part of r + A theta outside J's range is made as small as it can be (rows scaled by 1/|J|
    // to the others' units), and (theta, c) is the least-squares solution of least norm.
    const core::Vector Pr = chord.solve(r);
    const Eigen::Index q = A.cols();
    if (q == 0) {
      dx = -Pr;
      dx += N * (w * ((-plane - normal.dot(dx)) / w.squaredNorm()));
    } else {
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
    }
    r_previous = r;
    y += dx;
    if (!y.allFinite()) break;
  }
  y = best;
  return false;
}

BranchPointDetector::Locator::Locator(const ScaledProblem& problem, ScaledProblem* own,
                                      const ContinuationOptions& options,
                                      const ContinuationHooks& hooks)
    : problem_(problem), own_(own), options_(options), hooks_(hooks) {
  // What the chord steps leave is finished by Gauss-Newton that keeps its Jacobian while it
  // contracts (core::NewtonOptions::reuse_jacobian), to the verifier's tolerance: a located
  // point's correction within max_iterations 10, a probe's within 5 (the probes that converged
  // on the contact bar at 100 intervals took at most 4 iterations of the loop's corrector; the
  // ones that did not, 6 to 10).
  core::NewtonOptions newton = options.verification.corrector_options();
  newton.reuse_jacobian = true;
  newton.max_iterations = 10;
  finisher_ = core::make_corrector("eigen", newton);
  newton.max_iterations = 5;
  probe_finisher_ = core::make_corrector("eigen", newton);
}

void BranchPointDetector::Locator::run(Job job, std::vector<BranchPointReport>& found) {
  if (own_) own_->set_units(job.scale, job.residual_factor);
  last_jacobian_ = std::move(job.last_jacobian);
  jacobian_scale_ = job.jacobian_scale;
  found_ = &found;
  locate(job.polyline, job.sign_change);
  found_ = nullptr;
}

double BranchPointDetector::Locator::null_cutoff() const {
  // The rank report's: relative to the branch's Jacobian scale (verify()).
  return options_.rank.relative_threshold * jacobian_scale_;
}

// What add() hands over: the point and its Jacobian in the loop's units of that moment.
struct BranchPointDetector::Point {
  int index = 0;
  core::Vector z, tangent;
  core::Matrix jacobian;
  double arclength = 0;
  core::Vector scale, residual_factor;  // ScaledProblem::scale(), residual_factor() then
};

BranchPointDetector::BranchPointDetector(const ScaledProblem& problem,
                                         const ContinuationOptions& options,
                                         const ContinuationHooks& hooks, core::Corrector&)
    : problem_(problem), options_(options), unit_scale_(problem.unit_scale()) {
  std::unique_ptr<core::Problem> copy =
      options.branch_points.background ? problem.base().clone() : nullptr;
  if (!copy) {
    locator_ = std::make_unique<Locator>(problem, nullptr, options, hooks);
    return;
  }
  worker_base_ = std::move(copy);
  worker_problem_ = std::make_unique<ScaledProblem>(*worker_base_, problem);
  locator_ = std::make_unique<Locator>(*worker_problem_, worker_problem_.get(), options, hooks);
  locating_ = std::make_unique<core::SerialQueue>();
  sampling_ = std::make_unique<core::SerialQueue>();
}

BranchPointDetector::~BranchPointDetector() {
  // A loop that ends normally has waited (finish()); one that threw leaves the tasks not begun.
  // The sampling thread pushes onto the locating one: it stops first.
  sampling_.reset();
  locating_.reset();
}

void BranchPointDetector::wait_for_samples() const {
  if (sampling_) sampling_->wait();
}

const std::vector<TestFunctionSample>& BranchPointDetector::samples() const {
  wait_for_samples();
  return samples_;
}

double BranchPointDetector::jacobian_scale() const {
  wait_for_samples();
  return jacobian_scale_;
}

double BranchPointDetector::last_value() const {
  wait_for_samples();
  return samples_.empty() ? std::numeric_limits<double>::quiet_NaN() : samples_.back().tau.value;
}

void BranchPointDetector::restore(std::vector<TestFunctionSample> samples, double jacobian_scale) {
  wait_for_samples();
  samples_ = std::move(samples);
  jacobian_scale_ = jacobian_scale;
  last_jacobian_.resize(0, 0);
}

std::vector<BranchPointReport> BranchPointDetector::take() {
  if (sampling_) sampling_->rethrow();
  if (locating_) locating_->rethrow();
  const std::lock_guard<std::mutex> lock(found_mutex_);
  std::vector<BranchPointReport> out = std::move(found_);
  found_.clear();
  return out;
}

std::vector<BranchPointReport> BranchPointDetector::finish() {
  if (sampling_) sampling_->wait();  // its brackets are on the locating queue by then
  if (locating_) locating_->wait();
  return take();
}

void BranchPointDetector::submit(std::vector<Sample> polyline, bool sign_change,
                                 const core::Vector& scale, const core::Vector& residual_factor) {
  Job job;
  job.polyline = std::move(polyline);
  job.sign_change = sign_change;
  job.last_jacobian = last_jacobian_;
  job.jacobian_scale = jacobian_scale_;
  job.scale = scale;
  job.residual_factor = residual_factor;
  const auto run = [this](Job& j) {
    std::vector<BranchPointReport> out;
    locator_->run(std::move(j), out);
    const std::lock_guard<std::mutex> lock(found_mutex_);
    for (BranchPointReport& r : out) found_.push_back(std::move(r));
  };
  if (!locating_) {
    run(job);
    return;
  }
  locating_->push([run, job = std::move(job)]() mutable { run(job); });
}

void BranchPointDetector::add(int index, const core::Vector& z, const core::Vector& tangent,
                              const core::Matrix& J, double arclength) {
  Point p;
  p.index = index;
  p.z = z;
  p.tangent = tangent;
  p.jacobian = J;
  p.arclength = arclength;
  p.scale = problem_.scale();
  p.residual_factor = problem_.residual_factor();
  if (!sampling_) {
    sample(std::move(p));
    return;
  }
  sampling_->push([this, p = std::move(p)]() mutable { sample(std::move(p)); });
}

void BranchPointDetector::sample(Point p) {
  // Everything the detector keeps and compares is in the unit scale (scaled_problem.hpp): the
  // loop's units may follow the point (LocalScale), and a test function of J in the point's own
  // units would change from sample to sample with the units alone (the period column and the
  // equations in units of the amplitude).
  const core::Vector f = p.scale.cwiseQuotient(unit_scale_);
  Sample sample;
  sample.index = p.index;
  sample.z = p.z.cwiseProduct(f);
  sample.tangent = p.tangent.cwiseProduct(f).normalized();
  sample.s = p.arclength;
  last_jacobian_ = jacobian_in_unit_scale(p.jacobian, f, p.residual_factor);
  // One scale for the whole branch (J may vanish at a branch point: a per-point norm would hide
  // it): the Frobenius norm of the first point's Jacobian.
  if (!(jacobian_scale_ > 0))
    jacobian_scale_ = last_jacobian_.norm() > 0 ? last_jacobian_.norm() : 1.0;
  sample.tau = bordered_test_function(last_jacobian_, sample.tangent, jacobian_scale_,
                                      samples_.empty() ? nullptr : &samples_.back().tau, true);
  samples_.push_back(std::move(sample));
  if (samples_.size() > 3) samples_.erase(samples_.begin());
  const std::size_t k = samples_.size();
  if (k >= 2) {
    const Sample& a = samples_[k - 2];
    const Sample& b = samples_[k - 1];
    if (b.tau.continued && a.tau.value * b.tau.value < 0) {
      submit({a, b}, true, p.scale, p.residual_factor);
      samples_.erase(samples_.begin(), samples_.end() - 1);
      return;
    }
  }
  if (k == 3) {
    const double fa = std::abs(samples_[0].tau.value), fb = std::abs(samples_[1].tau.value),
                 fc = std::abs(samples_[2].tau.value);
    if (fb < options_.branch_points.dip_ratio * std::min(fa, fc)) {
      submit(samples_, false, p.scale, p.residual_factor);
      samples_.erase(samples_.begin(), samples_.end() - 1);
    }
  }
}

bool BranchPointDetector::Locator::subspace_correct(const Chord& chord, const core::Vector& normal,
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

BranchPointDetector::Evaluation BranchPointDetector::Locator::evaluate(
    const std::vector<Sample>& polyline, double s, const TestFunctionValue& reference,
    const Chord* initial, const Evaluation* last, const Evaluation* near) {
  Evaluation e;
  std::size_t i = 0;
  while (i + 2 < polyline.size() && s > polyline[i + 1].s) ++i;
  const Sample& a = polyline[i];
  const Sample& b = polyline[i + 1];
  const double length = b.s - a.s;
  const double fraction = length > 0 ? std::clamp((s - a.s) / length, 0.0, 1.0) : 0.0;
  const core::Vector segment = b.z - a.z;
  const core::Vector through = a.z + fraction * segment;
  const core::Vector normal = segment.normalized();
  const core::Vector f = factor();
  e.s = s;
  // Start: the cubic Hermite interpolant of the two samples and their tangents (error O(L^4) in
  // the chord length L, where the chord's own is O(L^2)), moved onto the hyperplane.
  {
    const double L = segment.norm(), t = fraction;
    const core::Vector ta = a.tangent.dot(segment) < 0 ? core::Vector(-a.tangent) : a.tangent;
    const core::Vector tb = b.tangent.dot(segment) < 0 ? core::Vector(-b.tangent) : b.tangent;
    e.z = (2 * t * t * t - 3 * t * t + 1) * a.z + (t * t * t - 2 * t * t + t) * L * ta +
          (-2 * t * t * t + 3 * t * t) * b.z + (t * t * t - t * t) * L * tb;
    e.z += normal * normal.dot(through - e.z);
    if (!e.z.allFinite() || a.tangent.size() != a.z.size() || b.tangent.size() != b.z.size())
      e.z = through;
  }
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
  if (!chord || !chord_correct(*chord, normal, through, e.z)) {
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

void BranchPointDetector::Locator::locate(const std::vector<Sample>& polyline, bool sign_change) {
  const auto started = std::chrono::steady_clock::now();
  const core::EvaluationCounters& counters = problem_.base().counters();
  const long jacobians_before = counters.jacobians, residuals_before = counters.residuals;
  const BranchPointOptions& o = options_.branch_points;
  // Located when |tau| is 1e-3 of the rank report's relative threshold: J is singular there at
  // the resolution the verification uses, with a margin, and the period of a contact-bar point
  // within ~3e-8 (at 100 intervals: 3.6 + 2.8e-9, 3.5 - 3.9e-10, 3.2 - 2.8e-8). Below that the
  // finite-difference noise of the test function (4e-9..8e-9 at T = 3.6) stalls the iteration:
  // at 1e-4 of it the location spent 6 more evaluations there for nothing. Near the root a
  // step costs one Jacobian and a few residuals (tangent predictor from the nearest evaluation).
  const double located_value = 1e-3 * options_.rank.relative_threshold;
  BranchPointReport report;
  report.sign_change = sign_change;
  // Each correction starts with chord steps on the last Jacobian evaluated (Chord): the
  // bracket is short, so it is close; the loop's corrector takes over when they stall.
  std::shared_ptr<const Chord> chord;
  if (last_jacobian_.size() > 0)
    chord = std::make_shared<const Chord>(last_jacobian_, null_cutoff());
  // The best point so far: the sampled one with the smallest |tau|.
  core::Vector best_z, best_tangent;
  core::Matrix best_jacobian;               // empty: not kept (a sample before the last)
  std::shared_ptr<const Chord> best_chord;  // of best_jacobian, when a sample's
  int best_done = -1;                       // when an evaluation's: its index in done
  double best_s = 0, best_value = std::numeric_limits<double>::infinity();
  for (const Sample& p : polyline)
    if (std::abs(p.tau.value) < std::abs(best_value)) {
      best_z = p.z;
      best_tangent = p.tangent;
      best_s = p.s;
      best_value = p.tau.value;
      const bool last = &p == &polyline.back();
      best_jacobian = last ? last_jacobian_ : core::Matrix();
      best_chord = last ? chord : nullptr;
    }
  std::vector<Evaluation> done;  // every corrected evaluation, for the next one's start
  const auto keep = [&](Evaluation& e, double s) {
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
  };
  const auto last = [&]() -> const Evaluation* { return done.empty() ? nullptr : &done.back(); };
  // The corrected evaluation nearest to s when it is nearer than every sample of the polyline.
  const auto nearest = [&](double s) -> const Evaluation* {
    double distance = std::numeric_limits<double>::infinity();
    for (const Sample& p : polyline) distance = std::min(distance, std::abs(p.s - s));
    const Evaluation* best = nullptr;
    for (const Evaluation& e : done)
      if (std::abs(e.s - s) < distance) {
        distance = std::abs(e.s - s);
        best = &e;
      }
    return best;
  };
  // Every value seen, for the minimisation of |tau| (a dip, or a secant iteration whose
  // singular triplet stopped following the reference's).
  std::vector<std::pair<double, double>> seen;  // (s, |tau|)
  for (const Sample& p : polyline) seen.emplace_back(p.s, std::abs(p.tau.value));
  // The test function's value at the known point (sample or evaluation) nearest to s: the
  // reference that orients an evaluation at s (and starts its inverse iteration). Each value is
  // oriented like its reference's, so the values of a chain of continued links share one sign
  // convention, and a sign change between any two of them is a crossing.
  const auto tau_near = [&](double s) {
    if (const Evaluation* e = nearest(s)) return e->tau;
    const Sample* closest = &polyline.front();
    for (const Sample& p : polyline)
      if (std::abs(p.s - s) < std::abs(closest->s - s)) closest = &p;
    return closest->tau;
  };
  int steps = 0;
  // Secant steps on the signed test function, regula falsi (Illinois: the stale end's value
  // halved) once two values of opposite signs bracket the root. A sign change starts bracketed
  // by its two samples. A dip starts from its smallest sample and an evaluation at 1 % of the
  // way towards its smaller neighbour: near the root tau is linear in s over a short stretch
  // only (other singular values take over farther out), so the secant through the two
  // extrapolates to it where a fit through the three samples does not (on the contact bar at
  // 100 intervals the V through the samples of the dip at T = 3.6 put it 0.022 off, 4.7 times
  // the distance of the smallest sample; the secant through that sample and one 1e-3 away put
  // it 1e-6 off).
  bool root_finding = sign_change;
  bool bracketed = sign_change;
  double s_prev = 0, f_prev = 0, s_last = 0, f_last = 0;
  const double s_min = polyline.front().s, s_max = polyline.back().s;
  if (sign_change) {
    s_prev = polyline[0].s;
    f_prev = polyline[0].tau.value;
    s_last = polyline[1].s;
    f_last = polyline[1].tau.value;
  } else if (polyline.size() == 3) {
    const Sample& middle = polyline[1];
    const bool right = std::abs(polyline[2].tau.value) < std::abs(polyline[0].tau.value);
    const double delta = 0.01 * (right ? polyline[2].s - middle.s : polyline[0].s - middle.s);
    const double s = middle.s + delta;
    Evaluation e = evaluate(polyline, s, middle.tau, chord.get(), last(), nearest(s));
    ++steps;
    if (e.ok) {
      keep(e, s);
      seen.emplace_back(s, std::abs(e.tau.value));
      s_prev = middle.s;
      f_prev = middle.tau.value;
      s_last = s;
      f_last = e.tau.value;
      root_finding = e.tau.continued;
      bracketed = f_prev * f_last < 0;
    }
  }
  if (root_finding) {
    // A root brings |tau| down superlinearly; a sign change that is a jump of tau (the
    // finite-difference Jacobian across a change of the contact sequence) or a dip that is not
    // a root does not: three evaluations in a row that do not halve the smallest |tau| end the
    // iteration.
    double smallest = std::min(std::abs(f_prev), std::abs(f_last));
    int stale = 0;
    bool left_range = false;
    while (steps < o.max_location_steps && std::abs(s_last - s_prev) > o.location_tolerance &&
           stale < 3 && !(std::abs(best_value) <= located_value)) {
      double s = (s_prev * f_last - s_last * f_prev) / (f_last - f_prev);
      if (bracketed) {
        const double lo = std::min(s_prev, s_last), hi = std::max(s_prev, s_last);
        if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);
      } else if (!(s > s_min && s < s_max)) {
        left_range = true;
        break;
      }
      Evaluation e = evaluate(polyline, s, tau_near(s), chord.get(), last(), nearest(s));
      ++steps;
      if (!e.ok) break;
      keep(e, s);
      seen.emplace_back(s, std::abs(e.tau.value));
      if (std::abs(e.tau.value) < 0.5 * smallest) {
        smallest = std::abs(e.tau.value);
        stale = 0;
      } else {
        ++stale;
      }
      if (!e.tau.continued) break;
      if (e.tau.value == 0) {
        seen.clear();
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
                        std::abs(best_value) <= located_value))
      seen.clear();
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
    // A minimum that stays flat above the rank threshold is a jump of the finite-difference test
    // function, not a root: three evaluations in a row that neither halve the smallest value nor
    // exceed twice it end the iteration (on the contact bar at 100 intervals the unverified
    // candidates at T = 3.332 and 3.142 read 1.2e-4..1.5e-4 and 5.5e-4..6.6e-4 at each of their
    // six V-fit evaluations; the verified dip at 3.6 starts 4-5 times above its sampled value).
    // Below the threshold the iteration is at the noise and keeps its six.
    int flat = 0;
    bool golden = false;
    while (steps < o.max_location_steps && sc - sa > o.location_tolerance && fb > located_value &&
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
      Evaluation e = evaluate(polyline, s, tau_near(s), chord.get(), last(), nearest(s));
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
  report.location_steps = steps;
  report.test_value = best_value;
  report.arclength = best_s;
  report.after_point = polyline.front().index;
  for (const Sample& p : polyline)
    if (p.s <= best_s) report.after_point = p.index;
  if (report.after_point == polyline.back().index && polyline.size() > 1)
    report.after_point = polyline[polyline.size() - 2].index;
  if (best_done >= 0) best_chord = done[static_cast<std::size_t>(best_done)].chord;
  verify(report, best_z, best_tangent, best_jacobian, best_chord.get());
  report.jacobian_evaluations = counters.jacobians - jacobians_before;
  report.residual_evaluations = counters.residuals - residuals_before;
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  found_->push_back(std::move(report));
}

void BranchPointDetector::Locator::verify(BranchPointReport& report, const core::Vector& z,
                                          const core::Vector& tangent, core::Matrix J,
                                          const Chord* chord_of_j) {
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
  // through the stepped point orthogonal to d. A direction is real when the corrected point is
  // a solution within h / drift_ratio of z: the hyperplane, which misses the traced branch near
  // z, met another family near the stepped point. Its secant from z gives the angle to t. Each
  // probe first takes chord steps on J with J's columns along the learned kinks re-differenced
  // at the stepped point and secant updates (chord_correct: one residual each; d is in J's null
  // space, so the hyperplane row is met exactly), then, when they stall, the loop's corrector
  // (its tolerance and iteration budget, fresh Jacobians; the verifier's 60 linear iterations
  // made failed probes the main cost of a branch point, measured on the contact bar at 100
  // intervals). There, stepping 1e-3 off a located point crosses a kink of F in every direction:
  // the chord steps alone finished none of 62 probes, each then took a Jacobian (about 20
  // residuals); with the kink learned at the first probe, 56 of 62 finish in 4-9 residuals.
  std::optional<Chord> own_chord;
  if (!chord_of_j) own_chord.emplace(J, null_cutoff());
  const Chord& chord = chord_of_j ? *chord_of_j : *own_chord;
  const core::VerifyOptions& v = options_.verification;
  const double h = options_.branch_points.probe_step;
  double smallest = std::numeric_limits<double>::infinity();
  int attached = 0;
  int subspace_done = 0, subspace_failed = 0;
  // Directions along which J changes between the located point and its probes (learned below).
  core::Matrix kinks(z.size(), 0);
  constexpr Eigen::Index max_kinks = 4;
  int learned = 0;
  for (int i = 0; i < std::min(candidates, options_.branch_points.max_probes); ++i) {
    const core::Vector d = svd.matrixU().col(i);
    const core::Vector stepped = z + h * d;
    core::Vector y = stepped;
    const bool okc = chord_correct(chord, d, stepped, y, &kinks);
    // The subspace stage is skipped once it has failed on at least two of this point's probes
    // and on more than two thirds of them (on the contact bar at 100 intervals it finished
    // 34 of 62 probes, 2 of 19 at T = 3.2).
    // Nor is it tried when a whole Jacobian costs no more residuals than one differencing along
    // N (a compressed finite-difference Jacobian, core/README.md): the finisher is then as cheap.
    const bool try_subspace =
        !(subspace_failed >= 2 && subspace_failed > 2 * subspace_done) &&
        !(jacobian_residuals_ > 0 && jacobian_residuals_ <= chord.null_space.cols() + 1);
    const bool oks = !okc && try_subspace && subspace_correct(chord, d, stepped, y, 4);
    if (!okc && try_subspace) ++(oks ? subspace_done : subspace_failed);
    if (!okc && !oks) {
      const core::BorderedSystem on_plane(
          problem_,
          {core::BorderRow::hyperplane(d.cwiseProduct(f).normalized(), stepped.cwiseQuotient(f))});
      core::Vector y_local = y.cwiseQuotient(f);
      const core::NewtonSummary s = probe_finisher_->solve(on_plane, y_local);
      if (!s.converged() || !y_local.allFinite()) continue;
      y = y_local.cwiseProduct(f);
    }
    if ((y - z).norm() > h / v.drift_ratio) continue;
    ++attached;
    if (!okc && learned < 3) {
      // The probe needed fresh Jacobians: J(y) differs from J where the step crossed a kink of
      // F. Its leading right singular vectors (singular values above 1e-2 of the largest, at
      // most three, of D = J(y) - J) are differenced at the next probes' starts. On the contact bar
      // at 100 intervals D has one such direction, the same at every probe of a point (the period's
      // column: its second singular value is 1e-5.. 1e-2 of its first, 200..300 against |J|
      // = 1.1e4).
      ++learned;
      core::Matrix Jy;
      if (problem_.jacobian(y.cwiseQuotient(f), Jy) == core::EvalStatus::ok) {
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

}  // namespace backbone::continuation
