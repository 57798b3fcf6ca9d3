#include "continuation/branch_points/branch_points.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include "continuation/internal/branch_point_locator.hpp"
#include "core/job_queue.hpp"
#include "core/rank/few_singular_values.hpp"

namespace backbone::continuation {

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
    locator_ = std::make_unique<branch_point::Locator>(problem, nullptr, options, hooks);
    return;
  }
  worker_base_ = std::move(copy);
  worker_problem_ = std::make_unique<ScaledProblem>(*worker_base_, problem);
  locator_ = std::make_unique<branch_point::Locator>(*worker_problem_, worker_problem_.get(),
                                                     options, hooks);
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

int BranchPointDetector::brackets() const {
  wait_for_samples();
  return brackets_;
}

void BranchPointDetector::restore(std::vector<TestFunctionSample> samples, double jacobian_scale,
                                  int brackets) {
  wait_for_samples();
  samples_ = std::move(samples);
  jacobian_scale_ = jacobian_scale;
  brackets_ = brackets;
  {
    const std::lock_guard<std::mutex> lock(found_mutex_);
    settled_ = brackets;
  }
  last_jacobian_.resize(0, 0);
}

std::vector<BranchPointReport> BranchPointDetector::take(int* settled) {
  if (sampling_) sampling_->rethrow();
  if (locating_) locating_->rethrow();
  const std::lock_guard<std::mutex> lock(found_mutex_);
  std::vector<BranchPointReport> out = std::move(found_);
  found_.clear();
  if (settled) *settled = settled_;
  return out;
}

std::vector<BranchPointReport> BranchPointDetector::finish(int* settled) {
  if (sampling_) sampling_->wait();  // its brackets are on the locating queue by then
  if (locating_) locating_->wait();
  return take(settled);
}

void BranchPointDetector::submit(std::vector<Sample> polyline, bool sign_change,
                                 const core::Vector& scale, const core::Vector& residual_factor) {
  branch_point::Job job;
  job.polyline = std::move(polyline);
  job.sign_change = sign_change;
  job.last_jacobian = last_jacobian_;
  job.jacobian_scale = jacobian_scale_;
  job.scale = scale;
  job.residual_factor = residual_factor;
  const int bracket = brackets_++;
  const auto run = [this, bracket](branch_point::Job& j) {
    std::vector<BranchPointReport> out;
    locator_->run(std::move(j), out);
    const std::lock_guard<std::mutex> lock(found_mutex_);
    for (BranchPointReport& r : out) {
      r.bracket = bracket;
      found_.push_back(std::move(r));
    }
    settled_ = bracket + 1;
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
  last_jacobian_ = branch_point::jacobian_in_unit_scale(p.jacobian, f, p.residual_factor);
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

}  // namespace backbone::continuation
