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
//     of the rank threshold, the bracket below location_tolerance, or |tau| stops falling;
//   - the located point is verified with the rank report and probes on the located point's
//     Jacobian, whose columns along the kinks of F that earlier probes crossed are re-differenced
//     at each probe's start: dimension = verified dimension - 1 (the directions beyond the traced
//     tangent),
//     and each extra direction is probed once more to find the attached family's secant, whose
//     angle to the traced tangent is tangent_angle.
//
//   BranchPointDetector detector(scaled_problem, options, hooks, corrector);
//   detector.add(index, z, tangent, J, arclength);   // after every accepted point
//   for (BranchPointReport& r : detector.take()) use(r.x, r.attached_dimension, r.tangent_angle);
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "continuation/branch.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/newton.hpp"
#include "core/rank_report.hpp"

namespace backbone::continuation {

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
  // Located candidates so far (in the problem's own unknowns), in order; cleared.
  std::vector<BranchPointReport> take();
  // Test-function value at the last added point (NaN before the first).
  double last_value() const;
  // What add() remembers between points, for a restart that must continue bit for bit: the
  // samples kept (points and tangents in the unit scale) and the Jacobian scale (0 before the
  // first point). restore() puts them back.
  const std::vector<TestFunctionSample>& samples() const { return samples_; }
  double jacobian_scale() const { return jacobian_scale_; }
  void restore(std::vector<TestFunctionSample> samples, double jacobian_scale);

 private:
  using Sample = TestFunctionSample;
  struct Evaluation;
  struct Chord;
  // The loop's units relative to the unit scale (ScaledProblem::scale() ./ unit_scale()).
  core::Vector factor() const;
  // J of the loop's problem (its current units) in the unit scale.
  core::Matrix in_unit_scale(const core::Matrix& J) const;
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
  const ContinuationOptions& options_;
  const ContinuationHooks& hooks_;
  core::Corrector& corrector_;
  std::vector<Sample> samples_;  // the last three points
  std::vector<BranchPointReport> found_;
  double jacobian_scale_ = 0;    // Frobenius norm of the first point's Jacobian (unit scale)
  core::Matrix last_jacobian_;   // the last sample's, unit scale (empty after restore())
  long jacobian_residuals_ = 0;  // residuals the last Jacobian evaluate() computed took (0: none)
  std::unique_ptr<core::Corrector> finisher_, probe_finisher_;  // after chord steps stall
};

}  // namespace backbone::continuation
