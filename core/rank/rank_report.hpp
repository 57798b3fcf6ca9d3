// How many dimensions does the solution set have near a point? A rank report of the Jacobian.
//
// The numerical rank of J (m x n) at a converged point comes from its singular values with a
// relative threshold (tau * sigma_max, tau documented in RankOptions). nullity = n - rank is
// the *candidate* dimension of the solution manifold. Because a rank count on a degenerate
// residual says nothing (a double root, core/README.md, section 'Shooting formulations'),
// verify_null_directions steps along each candidate null direction, re-corrects F plus the
// hyperplane through the stepped point orthogonal to that direction (a BorderedSystem with one
// row, bordered_system.hpp), and counts the directions along which nearby solutions really
// exist: the probes, core/rank/probes.hpp (included here). The smallest singular values come from
// core/rank/few_singular_values.hpp when RankOptions::full_spectrum is false.
//
//   Matrix J; problem.jacobian(x, J);
//   RankReport rep = rank_report(J, RankOptions{});
//   const VerifyOptions verify;
//   auto verifier = make_verifier(verify, RankOptions{});  // eigen, least squares, cut-off
//   verify_null_directions(problem, x, *verifier, verify, rep);
//   fmt::print("nullity {} verified {}\n", rep.nullity, rep.verified_dimension);
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/rank/probes.hpp"  // VerifyOptions, make_verifier, verify_null_directions
#include "core/solvers/newton.hpp"
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
