// Probes: does the solution set of F(x) = 0 really extend along a candidate null direction?
//
// A rank report (rank_report.hpp) counts the candidate directions of the solution set at x from
// the Jacobian's small singular values; a rank count on a degenerate residual says nothing (a
// double root has J = 0). A probe steps from x by h along a candidate direction d, re-corrects F
// plus the hyperplane through the stepped point orthogonal to d (a BorderedSystem with one row,
// bordered_system.hpp) and calls d real when the corrected point is a solution near the stepped
// one: the solution set passes there. verify_null_directions probes every candidate of a report
// and fills its verified dimension; VerifyOptions holds the step, the tests and the settings of
// the corrector that does this (make_verifier).
//
//   RankReport rep = rank_report(J, RankOptions{});
//   const VerifyOptions verify;
//   auto verifier = make_verifier(verify, RankOptions{});  // eigen, least squares, cut-off
//   verify_null_directions(problem, x, *verifier, verify, rep);
//   fmt::print("nullity {} verified {}\n", rep.nullity, rep.verified_dimension);
#pragma once

#include <limits>
#include <memory>

#include "core/problem.hpp"
#include "core/solvers/newton.hpp"
#include "core/types.hpp"

namespace backbone::core {

struct RankReport;   // rank_report.hpp
struct RankOptions;  // rank_report.hpp

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
// equations in n unknowns, solved in the least-squares sense) with options.corrector_options(),
// its singular values below rank.relative_threshold * sigma_max treated as zero
// (NewtonOptions::rank_cutoff), as the report they verify treated them. A probe borders J with
// one row, so its system keeps the family's other null directions; a cut-off below theirs
// inverts them, and their singular values (round-off of an exact Jacobian, 1e-8 of
// differences) then decide where the probe lands (core/README.md, 'Rank reports').
std::unique_ptr<Corrector> make_verifier(const VerifyOptions& options, const RankOptions& rank);

// One probe of the verification from x (as verify_null_directions runs it for a direction): a
// step of h along d, re-corrected on the hyperplane through the stepped point, its Jacobians
// refused beyond |h| / drift_ratio of x. found: converged (F within residual_tolerance, on the
// hyperplane) within drift_ratio |h| of the stepped point.
struct NeighbourProbe {
  bool converged = false;
  bool found = false;
  double residual = std::numeric_limits<double>::quiet_NaN();  // ||F||_inf at the end
  double drift = std::numeric_limits<double>::infinity();      // |end - stepped| / |h|
  Vector point;  // the corrected point (empty when not finite)
};
NeighbourProbe probe_neighbour(const Problem& problem, const Vector& x, const Vector& d, double h,
                               Corrector& corrector, const VerifyOptions& options);

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
// with chord steps on its factorization (core/solvers/newton.hpp): a probe steps by `step`, so J(x)
// is as good as a fresh one there, and a probe costs a few residuals instead of a Jacobian.
// neighbour (a solution already known near x: the branch's previous point) stands in for the
// probe of a direction d it verifies by the same tests, as if a probe had stepped by
// h = d . (neighbour - x) and been corrected onto it: ||F(neighbour)||_inf <= residual_tolerance
// and |neighbour - x - h d| <= drift_ratio |h|. On a curve the one candidate is the tangent,
// which the secant to the previous point verifies: one residual instead of a correction
// (core/README.md, 'Rank reports'). neighbour_residual: ||F(neighbour)||_inf when the caller
// has it (a branch recorded it with the point); NaN: evaluated here, once, and only when some
// direction passes the drift test on the neighbour.
void verify_null_directions(const Problem& problem, const Vector& x, Corrector& corrector,
                            const VerifyOptions& options, RankReport& report,
                            const Matrix* jacobian_at_x = nullptr,
                            const Vector* neighbour = nullptr,
                            double neighbour_residual = std::numeric_limits<double>::quiet_NaN());

}  // namespace backbone::core
