// Branch points along a traced curve: where another family of solutions attaches to it.
//
// Test function. At a regular point of a curve F(x) = 0 (F: R^n -> R^m, rank n - 1) the bordered
// matrix [J; t^T] has full column rank n; where another family attaches, J loses rank and so does
// [J; t^T]. The test function is the smallest singular value of [J / |J_0|_F; t^T] (J_0: the
// Jacobian at the branch's first point; scaled unknowns, so it has no units), signed by following
// the singular vectors from point to point (analytic SVD): at a simple branch point it changes
// sign. This also holds for a consistent overdetermined residual (least-squares shooting), where no
// determinant exists. J, t and the points are taken in the unit scale of the loop's problem
// (ScaledProblem::unit_scale()): when the loop's units follow the point (LocalScale), J in the
// point's units would change from sample to sample with the units alone.
//
// Detection, location, verification (continuation/README.md, section 'Branch points'):
//   - a sign change between consecutive points, or a dip (|tau_k| below dip_ratio times both
//     neighbours: a sampled minimum, whose depth depends on how close a step lands) brackets a
//     candidate;
//   - it is located on the branch by secant steps on the signed test function, each value
//     oriented by the nearest known one's singular vectors, from the sign change's two samples
//     or from a dip's smallest sample and a point 1 % of the way to its smaller neighbour,
//     Illinois regula falsi once bracketed; when the vectors stop following each other, by a
//     safeguarded V-fit of |tau| (|tau| ~ |s - s*| near a simple crossing) with golden-section
//     fall-back. Each evaluation is a point corrected on the hyperplane orthogonal to the
//     bracket's polyline (chord steps on the last Jacobian with secant updates first, then
//     Gauss-Newton that keeps its Jacobian while it contracts); it ends when |tau| is below 1e-3
//     of the rank threshold, the bracket below location_tolerance, or |tau| stops falling; with
//     an exact Jacobian the root is then found again on points whose components along the
//     attached directions are the branch's (branch_point_locator.hpp, refine_on_branch);
//   - the located point is verified with the rank report and probes on the located point's
//     Jacobian, whose columns along the kinks of F that earlier probes crossed are re-differenced
//     at each probe's start: dimension = verified dimension - 1 (the directions beyond the traced
//     tangent),
//     and each extra direction is probed once more to find the attached family's secant, whose
//     angle to the traced tangent is tangent_angle.
//
// Where: the test function and the brackets on the loop's thread at each point (the restart
// state holds the samples); location and verification on a second thread, on the problem's
// clone() set to the loop's units of the moment the candidate was bracketed, in the order of the
// brackets (options.branch_points.background; without a clone, on the loop's thread). Either way
// the rows are the same bits; take() returns those finished, finish() waits for the rest (the
// loop calls it when the branch ends, LoopSteps::add_pending_branch_points).
//
//   BranchPointDetector detector(scaled_problem, options, hooks, corrector);
//   detector.add(index, z, tangent, J, arclength);   // after every accepted point
//   for (BranchPointReport& r : detector.take()) use(r.x, r.attached_dimension, r.tangent_angle);
//   for (BranchPointReport& r : detector.finish()) use(r);   // when the branch ends
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::core {
class SerialQueue;  // core/job_queue.hpp
}  // namespace backbone::core

namespace backbone::continuation {

namespace branch_point {
class Locator;  // locates and verifies one candidate (branch_point_locator.hpp)
}  // namespace branch_point

// The signed test function at one point, with the singular vectors that fix its sign.
struct TestFunctionValue {
  double value = 0;  // +- sigma_min([J; t^T]) / sigma_max(J)
  core::Vector left, right;
  bool continued = true;  // false when the vectors did not follow the reference's (sign unknown)
};

// One point of the branch as the detector keeps it (the last three): its index, scaled point,
// unit tangent, test-function value and arclength. Part of a loop's restart state (restart.hpp).
struct TestFunctionSample {
  int index = 0;
  core::Vector z, tangent;
  TestFunctionValue tau;
  double s = 0;  // arclength
};

// Test function of J (m x n) and the unit tangent t: the smallest singular value of
// [J / scale; t^T]. With a reference (the previous point's value), the singular vectors are
// oriented like the reference's and the value is signed; without one it is positive.
// iterate: by a Krylov basis of inverse iteration on the QR factor, started from the
// reference's right vector (the SVD when it does not converge); else by the SVD.
TestFunctionValue bordered_test_function(const core::Matrix& J, const core::Vector& tangent,
                                         double scale, const TestFunctionValue* reference,
                                         bool iterate = false);

class BranchPointDetector {
 public:
  // problem: the loop's problem in scaled unknowns (its units may change between add() calls:
  // set_factor); corrector: the loop's (kept for the interface; location and probes use the
  // detector's own Gauss-Newton to the verifier's tolerance). Uses options.branch_points,
  // options.rank, options.verification (probe step, drift_ratio, tolerance);
  // hooks.describe_branch_point, when set, describes each verified point.
  BranchPointDetector(const ScaledProblem& problem, const ContinuationOptions& options,
                      const ContinuationHooks& hooks, core::Corrector& corrector);
  ~BranchPointDetector();

  // After each accepted point z, its unit tangent and its Jacobian, all in the problem's current
  // units, and its arclength. May locate and verify a candidate bracketed by this and the
  // previous points.
  void add(int index, const core::Vector& z, const core::Vector& tangent, const core::Matrix& J,
           double arclength);
  // Located candidates so far (in the problem's own unknowns), in order; cleared. Does not wait
  // for the worker's pending candidates. settled, when given: how many brackets have been
  // located or given up by then (BranchPointReport::bracket counts them from 0, in order), the
  // returned reports included.
  std::vector<BranchPointReport> take(int* settled = nullptr);
  // The rest: waits until every candidate handed to the worker is located and verified, then
  // take(). Rethrows what a location threw on the worker.
  std::vector<BranchPointReport> finish(int* settled = nullptr);
  // Test-function value at the last added point (NaN before the first).
  double last_value() const;
  // What add() remembers between points, for a restart that must continue bit for bit: the
  // samples kept (points and tangents in the unit scale) and the Jacobian scale (0 before the
  // first point). restore() puts them back.
  // They wait for the sampling thread to take every point added (one step of the loop's is
  // ample time for it).
  // brackets(): the candidates bracketed so far, located or not (the next one's
  // BranchPointReport::bracket).
  const std::vector<TestFunctionSample>& samples() const;
  double jacobian_scale() const;
  int brackets() const;
  void restore(std::vector<TestFunctionSample> samples, double jacobian_scale, int brackets);

 private:
  using Sample = TestFunctionSample;
  struct Point;  // what add() hands over: the point, its J, the units then
  // The test function at the point, and the brackets it closes (submit): on the sampling thread,
  // or here without one.
  void sample(Point p);
  // Hands a bracketed candidate to the locating thread, or locates it here without one.
  void submit(std::vector<Sample> polyline, bool sign_change, const core::Vector& scale,
              const core::Vector& residual_factor);
  void wait_for_samples() const;

  const ScaledProblem& problem_;  // read on the loop's thread only
  const ContinuationOptions& options_;
  const core::Vector unit_scale_;  // problem_.unit_scale(), for the sampling thread
  // The sampling thread's (the caller's without one); read after wait_for_samples().
  std::vector<Sample> samples_;  // the last three points
  double jacobian_scale_ = 0;    // Frobenius norm of the first point's Jacobian (unit scale)
  core::Matrix last_jacobian_;   // the last sample's, unit scale (empty after restore())
  int brackets_ = 0;             // candidates bracketed (submitted) so far
  std::mutex found_mutex_;
  std::vector<BranchPointReport> found_;  // located, not yet taken
  int settled_ = 0;                       // brackets located or given up (under found_mutex_)
  // With a clone() of the problem (options.branch_points.background): the copy and its view,
  // which the locator corrects in, and the two threads. Declared in this order so that the
  // sampling thread, which pushes onto the locating one, stops first.
  std::unique_ptr<core::Problem> worker_base_;
  std::unique_ptr<ScaledProblem> worker_problem_;
  std::unique_ptr<branch_point::Locator> locator_;  // branch_point_locator.hpp
  std::unique_ptr<core::SerialQueue> locating_;
  std::unique_ptr<core::SerialQueue> sampling_;
};

}  // namespace backbone::continuation
