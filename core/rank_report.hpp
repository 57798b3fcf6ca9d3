// How many dimensions does the solution set have near a point? A rank report of the Jacobian.
//
// The numerical rank of J (m x n) at a converged point comes from its singular values with a
// relative threshold (tau * sigma_max, tau documented in RankOptions). nullity = n - rank is
// the *candidate* dimension of the solution manifold. Because a rank count on a degenerate
// residual says nothing (a double root, core/README.md, section 'Shooting formulations'),
// verify_null_directions steps along each candidate null direction, re-corrects F plus the
// hyperplane through the stepped point orthogonal to that direction (a BorderedSystem with one
// row, bordered_system.hpp), and counts the directions along which nearby solutions really
// exist. VerifyOptions also carries the settings of the corrector that does this (make_verifier).
//
//   Matrix J; problem.jacobian(x, J);
//   RankReport rep = rank_report(J, RankOptions{});
//   const VerifyOptions verify;
//   auto verifier = make_verifier(verify);        // eigen, least squares, verify's tolerances
//   verify_null_directions(problem, x, *verifier, verify, rep);
//   fmt::print("nullity {} verified {}\n", rep.nullity, rep.verified_dimension);
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/newton.hpp"
#include "core/types.hpp"

namespace backbone::core {

struct RankOptions {
  // Relative threshold: sigma_i counts as zero when sigma_i <= relative_threshold * sigma_max.
  double relative_threshold = 1e-8;
  // Absolute floor: sigma_i also counts as zero when sigma_i <= absolute_threshold. A double
  // root has J ~ 0, so sigma_max itself is noise (finite-difference error ~ 1e-8) and a purely
  // relative threshold would count that noise as rank; set this to the Jacobian's noise level
  // there. Default 0: relative only.
  double absolute_threshold = 0;
  // false: compute sigma_max and only the smallest singular values up to one beyond the
  // threshold, with their right vectors (rank_report, core/README.md 'Rank reports'); the
  // other entries of RankReport::singular_values are NaN. For a report at every point of a
  // branch, where the full SVD cost a third of the trace at N = 160.
  bool full_spectrum = true;
  void validate() const;
};

struct VerifyOptions {
  // Step length along each null direction (scaled units). 1e-4: a family that is piecewise
  // affine with pieces that narrow as its grid is refined (the contact bar's) keeps a probe of
  // this length inside one piece, where one Jacobian corrects it; 1e-3 crossed pieces and
  // wandered off (core/README.md, 'Rank reports': 10 of 64 directions verified at N = 640 in
  // 105 s, 64 of 64 in 20 s at 1e-4).
  double step = 1e-4;
  double residual_tolerance = 1e-9;  // re-corrected point must reach this
  // A direction is real when the re-corrected point stays within drift_ratio * step of the
  // stepped point in the orthogonal complement (the solution set passes near it).
  double drift_ratio = 0.1;
  // The verifier's corrector (make_verifier): at most max_iterations, because degenerate
  // residuals converge linearly (the error halves per iteration at a double root), and it stops
  // at ||F||_inf <= corrector_tolerance_ratio * residual_tolerance, so that a converged probe
  // passes the residual_tolerance test with a margin.
  int max_iterations = 60;
  double corrector_tolerance_ratio = 0.1;
  void validate() const;
  // NewtonOptions' defaults with the two settings above, and chord steps (reuse_jacobian).
  NewtonOptions corrector_options() const;
};

// The corrector verify_null_directions is meant to run with: eigen (each probe has m + 1
// equations in n unknowns, solved in the least-squares sense) with options.corrector_options().
std::unique_ptr<Corrector> make_verifier(const VerifyOptions& options);

struct RankReport {
  Vector singular_values;  // descending (NaN where not computed: RankOptions::full_spectrum)
  double threshold = 0;    // value used: max(relative_threshold * sigma_max, absolute_threshold)
  double relative_threshold = 0;
  int rank = 0;
  int nullity = 0;              // num_unknowns - rank: candidate manifold dimension
  double gap = 0;               // sigma_rank / sigma_{rank+1} (inf when no small one)
  Matrix null_directions;       // n x nullity, orthonormal
  int verified_dimension = -1;  // -1 until verify_null_directions ran
  std::vector<bool> direction_verified;
  std::string summary() const;  // one line for logs: "rank 40/41, nullity 1 (verified 1), ..."
};

RankReport rank_report(const Matrix& J, const RankOptions& options);

// Fills verified_dimension and direction_verified. Evaluates the problem; never throws on
// numerical failure (a direction that fails to re-correct is simply not verified).
// Each direction d is probed at +h, and at -h when +h finds no neighbour: at a point on the
// boundary of a manifold (a grazing limit of a continuum) solutions lie on one side only.
// When some candidate directions fail, the basis of their span is rotated (same span, still
// orthonormal) onto the secants of their converged probes and probed again, because the SVD
// basis need not be aligned with the solution set (J = 0 at a double root); the directions
// that passed stay. null_directions is then replaced by the passed directions followed by the
// rotated ones, and direction_verified refers to it.
// The corrector must handle m + 1 equations in n unknowns: KINSOL only when m + 1 == n.
// jacobian_at_x (J of problem at x, when the caller has it) starts every probe's correction
// with chord steps on its factorization (core/newton.hpp): a probe steps by `step`, so J(x) is
// as good as a fresh one there, and a probe costs a few residuals instead of a Jacobian.
// neighbour (a solution already known near x: the branch's previous point) stands in for the
// probe of a direction d it verifies by the same tests, as if a probe had stepped by
// h = d . (neighbour - x) and been corrected onto it: ||F(neighbour)||_inf <= residual_tolerance
// and |neighbour - x - h d| <= drift_ratio |h|. On a curve the one candidate is the tangent,
// which the secant to the previous point verifies: one residual instead of a correction
// (core/README.md, 'Rank reports').
void verify_null_directions(const Problem& problem, const Vector& x, Corrector& corrector,
                            const VerifyOptions& options, RankReport& report,
                            const Matrix* jacobian_at_x = nullptr,
                            const Vector* neighbour = nullptr);

// The candidates where J(x) cannot give them: at a point where F is not differentiable (the
// grazing limit of a contact family, where a contact phase vanishes, forward differences mix
// the two sides and see fewer null directions than the family has). `into` is a direction
// along which the family is known to continue from x (a chord to a neighbouring point): the
// rank report of J at x + s step into, s = +1 and -1, the one of larger nullity, whose null
// directions verify_null_directions then probes from x itself. Empty report (nullity 0) when
// neither Jacobian can be evaluated.
RankReport rank_report_beside(const Problem& problem, const Vector& x, const Vector& into,
                              double step, const RankOptions& options);

}  // namespace backbone::core
