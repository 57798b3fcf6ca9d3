// Internal to backbone::continuation: the branch-point detector's locator (branch_points.hpp).
//
// A Locator takes a candidate the detector bracketed (a Job: the samples around it, the last
// Jacobian, the loop's units of that moment), locates it on the branch by secant steps on the
// signed test function and a V-fit of its modulus, and verifies the located point by the rank
// report and probes along the directions beyond the traced tangent (branch_points.hpp,
// 'Detection, location, verification'). Its corrections are chord steps on one Jacobian (Chord),
// Gauss-Newton with the columns along the null space re-differenced (subspace_correct), and the
// verifier's Newton corrector when those stall. Files: branch_point_locator.cpp (the location),
// branch_point_correctors.cpp (the corrections), branch_point_verify.cpp (the verification).
//
//   branch_point::Locator locator(problem, nullptr, options, hooks);
//   std::vector<BranchPointReport> found;
//   locator.run(std::move(job), found);   // appends the located candidate's report
#pragma once

#include <Eigen/QR>
#include <memory>
#include <vector>

#include "continuation/branch_points/branch_points.hpp"
#include "continuation/callbacks.hpp"
#include "continuation/options.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::continuation::branch_point {

using Sample = TestFunctionSample;

// J in units of factor (relative to the unit scale) and residual factor rf, in the unit scale:
// diag(rf) J diag(1 ./ factor).
inline core::Matrix jacobian_in_unit_scale(const core::Matrix& J, const core::Vector& factor,
                                           const core::Vector& rf) {
  core::Matrix out = J * factor.cwiseInverse().asDiagonal();
  if (rf.size() > 0) out = rf.asDiagonal() * out;
  return out;
}

// Chord corrections with one Jacobian J (the unit scale's, m x n): Gauss-Newton steps with J's
// rank-truncated least-squares solution of least norm, and, for the hyperplane row
// a . (y - anchor) = 0, a move in J's null space N towards a. The constraint is met after every
// step when a has a component in N (|N^T a| >= 1/2): a probe direction is one of N's, and a chord
// of the branch is close to its tangent, which is in N. One residual per step.
// The rank is revealed by a complete orthogonal decomposition (column-pivoted QR, then a QR of
// the kept rows: J P = Q [T 0; 0 0] Z), pivots below cutoff counting as zero: 0.34 ms for the
// 200 x 101 Jacobian of the contact bar at 100 intervals where the thin SVD takes 6 ms.
struct Chord {
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

struct Evaluation {
  bool ok = false;
  double s = 0;             // where on the bracket's polyline
  core::Vector z, tangent;  // unit scale
  core::Matrix jacobian;    // unit scale, at z
  TestFunctionValue tau;
  // The chord of `jacobian` (its SVD), made on first use (chord_of): by the next evaluation's
  // start and, at the best one, by the verification, which share it.
  mutable std::shared_ptr<const Chord> chord;
};

// What a location needs of the detector, copied when the candidate is bracketed: the loop goes
// on (and its units change) while the worker locates it.
struct Job {
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
class Locator {
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
  // verifier's corrector tolerance. polish: once within it, the steps go on while each cuts
  // |F| tenfold, and y is the converged iterate with the smallest |F| (a located point's period
  // to round-off: continuation/README.md, 'Branch points').
  bool chord_correct(const Chord& chord, const core::Vector& normal, const core::Vector& anchor,
                     core::Vector& y, const core::Matrix* kinks = nullptr,
                     bool polish = false) const;
  // A = J's columns along the kinks, differenced at y (F(y) = r in the unit scale), less J's
  // own: the start of chord_correct's secant updates. False when a residual fails.
  bool difference_kinks(const Chord& chord, const core::Matrix& kinks, const core::Vector& y,
                        const core::Vector& r, core::Matrix& A) const;
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
  // Locates the candidate bracketed by polyline's samples, verifies it, appends its report to
  // found_. Its steps, on one Location: start_secant, secant_steps (when the start is a root
  // finding one), minimise_modulus, verify_best.
  struct Location;
  struct Secant;
  void locate(const std::vector<Sample>& polyline, bool sign_change);
  // evaluate() at s from what the location has (its chord, last and nearest evaluations).
  Evaluation evaluate_at(Location& at, double s, const TestFunctionValue& reference);
  // The secant iteration's start: a sign change's two samples, or a dip's smallest sample and
  // an evaluation 1 % of the way to its smaller neighbour.
  Secant start_secant(Location& at, bool sign_change);
  // Secant steps, regula falsi once bracketed, until located or stalled.
  void secant_steps(Location& at, Secant& secant, double located_value);
  // V-fit and golden-section minimisation of |tau| around the smallest value seen.
  void minimise_modulus(Location& at, double located_value);
  // With an exact Jacobian: the root again, on the interpolant of two points on either side
  // corrected where J is not singular (locator.cpp, refine_on_branch).
  void refine_on_branch(Location& at);
  // Chord steps from y onto F = 0 and normal . (y - through) = 0 (unit scale) on one matrix,
  // chord (unit scale) or else J at y, pivots below cutoff times the largest dropped (0: at
  // round-off): the point z, and J there (one Jacobian, or two without chord). False when they
  // do not reach the verifier's corrector tolerance.
  bool correct_on_plane(const core::Vector& normal, const core::Vector& through, core::Vector y,
                        double cutoff, const core::Matrix* chord, core::Vector& z,
                        core::Matrix& J) const;
  // The report's location fields, then verify() at the best point.
  void verify_best(Location& at, BranchPointReport& report);
  // Verifies the located point z (its tangent and J, empty: evaluated here) and fills report's
  // verification fields (branch_point_verify.cpp). chord_of_j: J's Chord when the location made
  // it (nullptr: made here).
  void verify(BranchPointReport& report, const core::Vector& z, const core::Vector& tangent,
              core::Matrix J, const Chord* chord_of_j = nullptr);
  // Its steps. The rank report of J (report.nullity) and the orthonormal directions of its
  // candidate null space beyond the tangent t, the first `candidates` of which are probed.
  core::Matrix directions_beyond(const core::Matrix& J, const core::Vector& t,
                                 BranchPointReport& report, int& candidates) const;
  struct Probing;
  // One probe from stepped (z + h d) onto the hyperplane through it orthogonal to d: y, and
  // whether the chord steps alone finished it. False when no corrector converged.
  bool probe(const Chord& chord, const core::Vector& d, const core::Vector& stepped,
             Probing& probing, core::Vector& y, bool& by_chord) const;
  // Adds to kinks the directions along which J(y) differs from J.
  void learn_kinks(const core::Vector& y, const core::Matrix& J, core::Matrix& kinks) const;

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

}  // namespace backbone::continuation::branch_point
