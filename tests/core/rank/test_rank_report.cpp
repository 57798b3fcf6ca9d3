// Rank reports on known matrices and verification of candidate null directions: a regular
// circle and sphere (candidate = verified) and the double-root parabola, whose Jacobian is
// identically zero on the solution curve (candidate nullity 2, verified dimension 1), and the
// verifier's corrector settings carried by VerifyOptions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "core/errors.hpp"
#include "core/rank/rank_report.hpp"
#include "core/solvers/eigen_newton.hpp"
#include "core/solvers/kinsol_newton.hpp"
#include "tests/core/test_problems.hpp"

namespace backbone::core {
namespace {

using testing::DoubleRootParabola;
using testing::HalfPlane;
using testing::KinkedHalfPlane;
using testing::Sphere;

TEST(RankReport, DiagonalMatrixWithAClearGap) {
  Matrix J = Matrix::Zero(3, 4);
  J.diagonal() << 2.0, 1.0, 1e-10;
  const RankReport r = rank_report(J, RankOptions{});  // threshold 1e-8 * 2 = 2e-8
  EXPECT_EQ(r.rank, 2);
  EXPECT_EQ(r.nullity, 2);
  EXPECT_DOUBLE_EQ(r.threshold, 2e-8);
  EXPECT_NEAR(r.gap, 1e10, 1.0);  // sigma_2 / sigma_3 = 1 / 1e-10
  ASSERT_EQ(r.null_directions.rows(), 4);
  ASSERT_EQ(r.null_directions.cols(), 2);
  // Orthonormal and spanning {e3, e4}: J * N = 1e-10 at most, N^T N = I.
  EXPECT_LT((r.null_directions.transpose() * r.null_directions - Matrix::Identity(2, 2)).norm(),
            1e-14);
  EXPECT_LT(r.null_directions.topRows(2).norm(), 1e-14);
  EXPECT_EQ(r.verified_dimension, -1);
  EXPECT_NE(r.summary().find("rank 2/4, nullity 2"), std::string::npos) << r.summary();
}

// A tall matrix (m = 2n - 2, the contact bar's shape) with known singular values: J = U S V^T
// from orthonormal U, V (QR of fixed pseudo-random matrices), two of the values zero.
TEST(RankReport, TallMatrixHasItsKnownSingularValuesAndNullSpace) {
  const int n = 41, m = 2 * n - 2;
  std::srand(3);
  const Matrix U = Eigen::HouseholderQR<Matrix>(Matrix::Random(m, m)).householderQ();
  const Matrix V = Eigen::HouseholderQR<Matrix>(Matrix::Random(n, n)).householderQ();
  Vector s(n);
  for (int i = 0; i < n; ++i) s[i] = i < n - 2 ? std::pow(10.0, -6.0 * i / (n - 3)) : 0.0;
  const Matrix J = U.leftCols(n) * s.asDiagonal() * V.transpose();
  const RankReport r = rank_report(J, RankOptions{});  // threshold 1e-8, sigma_{n-2} = 1e-6
  EXPECT_EQ(r.rank, n - 2);
  EXPECT_EQ(r.nullity, 2);
  // A backward-stable SVD of J (rounded from U S V^T with ||J|| = 1): every value within a
  // small multiple of eps ||J|| of the exact one (measured 1e-15; 1e-14 leaves a margin).
  ASSERT_EQ(r.singular_values.size(), n);
  for (int i = 0; i < n; ++i) EXPECT_NEAR(r.singular_values[i], s[i], 1e-14) << i;
  // The null space is span of V's last two columns: the projectors agree to eps / gap, the
  // gap being sigma_{n-2} = 1e-6 (1e-9 allows the eps ||J|| / gap perturbation bound).
  const Matrix& N = r.null_directions;
  ASSERT_EQ(N.rows(), n);
  ASSERT_EQ(N.cols(), 2);
  EXPECT_LT((N.transpose() * N - Matrix::Identity(2, 2)).norm(), 1e-14);
  const Matrix exact = V.rightCols(2) * V.rightCols(2).transpose();
  EXPECT_LT((N * N.transpose() - exact).norm(), 1e-9);
}

// The report from the smallest values only (RankOptions::full_spectrum = false) against the
// exact decomposition J = U S V^T: tall (the contact bar's shape), a spectrum spread over six
// decades and a null space of `zeros` values at 1e-12; zeros = 9 fills the first block of
// eight, which must grow. sigma_max by Lanczos to 1e-10 (tolerance 1e-9 of it), the smallest
// values by inverse iteration on R^T R from a backward-stable QR (each within a small multiple
// of eps ||J|| = 1e-16; 1e-13 leaves a margin), the null span to eps / gap (gap 1e-6: 1e-9).
TEST(RankReport, SmallestValuesOnlyAgreeWithTheExactDecomposition) {
  const int n = 61, m = 2 * n - 2;
  std::srand(5);
  const Matrix U = Eigen::HouseholderQR<Matrix>(Matrix::Random(m, m)).householderQ();
  const Matrix V = Eigen::HouseholderQR<Matrix>(Matrix::Random(n, n)).householderQ();
  for (const int zeros : {1, 3, 9}) {
    Vector s(n);
    for (int i = 0; i < n; ++i)
      s[i] = i < n - zeros ? std::pow(10.0, -6.0 * i / (n - zeros - 1)) : 1e-12;
    const Matrix J = U.leftCols(n) * s.asDiagonal() * V.transpose();
    RankOptions options;
    options.full_spectrum = false;
    const RankReport r = rank_report(J, options);
    EXPECT_EQ(r.rank, n - zeros) << zeros;
    EXPECT_EQ(r.nullity, zeros);
    ASSERT_EQ(r.singular_values.size(), n);
    EXPECT_NEAR(r.singular_values[0], 1.0, 1e-9);
    EXPECT_TRUE(std::isnan(r.singular_values[n / 2])) << "not computed: NaN";
    for (int i = n - zeros - 1; i < n; ++i) EXPECT_NEAR(r.singular_values[i], s[i], 1e-13) << i;
    EXPECT_NEAR(r.gap, s[n - zeros - 1] / 1e-12, 1e-3 * r.gap);
    const Matrix& N = r.null_directions;
    ASSERT_EQ(N.cols(), zeros);
    EXPECT_LT((N.transpose() * N - Matrix::Identity(zeros, zeros)).norm(), 1e-12);
    const Matrix exact = V.rightCols(zeros) * V.rightCols(zeros).transpose();
    EXPECT_LT((N * N.transpose() - exact).norm(), 1e-9) << zeros;
  }
}

TEST(RankReport, ThresholdIsRelative) {
  // Same matrix scaled by 1e-6: the count must not change (a relative threshold).
  Matrix J(2, 3);
  J << 1, 2, 3, 2, 4, 6.000001;  // nearly rank 1: sigma_2 / sigma_1 ~ 3.2e-8
  for (double s : {1.0, 1e-6, 1e6}) {
    RankOptions o;
    o.relative_threshold = 1e-10;
    EXPECT_EQ(rank_report(s * J, o).rank, 2) << s;
    o.relative_threshold = 1e-5;
    EXPECT_EQ(rank_report(s * J, o).rank, 1) << s;
  }
}

TEST(RankReport, AbsoluteFloorIgnoresNoiseOfAVanishingJacobian) {
  // A Jacobian that is zero up to finite-difference noise (~1e-8): relative-only reports
  // rank 1; with an absolute floor above the noise it reports the true candidate nullity 2.
  Matrix J(1, 2);
  J << 3e-9, -1e-8;
  EXPECT_EQ(rank_report(J, RankOptions{}).rank, 1);
  RankOptions o;
  o.absolute_threshold = 1e-6;
  const RankReport r = rank_report(J, o);
  EXPECT_EQ(r.rank, 0);
  EXPECT_EQ(r.nullity, 2);
  EXPECT_EQ(r.threshold, 1e-6);
}

TEST(RankReport, ZeroMatrixHasFullNullity) {
  const RankReport r = rank_report(Matrix::Zero(1, 2), RankOptions{});
  EXPECT_EQ(r.rank, 0);
  EXPECT_EQ(r.nullity, 2);
  EXPECT_EQ(r.null_directions.cols(), 2);
}

TEST(RankReport, OptionsValidationNamesTheField) {
  RankOptions r;
  r.relative_threshold = 0;
  try {
    r.validate();
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "rank.relative_threshold");
  }
  VerifyOptions v;
  v.drift_ratio = 2;
  try {
    v.validate();
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "verify.drift_ratio");
  }
  r = {};
  r.absolute_threshold = -1;
  EXPECT_THROW(r.validate(), InputError);
  v = {};
  v.step = -1e-3;
  EXPECT_THROW(v.validate(), InputError);
  v = {};
  v.max_iterations = 0;
  try {
    v.validate();
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "verify.max_iterations");
  }
  v = {};
  v.corrector_tolerance_ratio = 0;
  EXPECT_THROW(make_verifier(v, RankOptions{}), InputError);
}

// The verifier's corrector follows VerifyOptions: its tolerance is ratio * residual_tolerance
// (defaults 0.1 * 1e-9 = 1e-10, what the continuation and the bench used by hand) and its
// iteration cap is max_iterations (default 60).
TEST(VerifyNullDirections, VerifierSettingsComeFromVerifyOptions) {
  VerifyOptions v;
  EXPECT_DOUBLE_EQ(v.corrector_options().residual_tolerance, 1e-10);
  EXPECT_EQ(v.corrector_options().max_iterations, 60);
  v.residual_tolerance = 1e-6;
  v.corrector_tolerance_ratio = 0.5;
  v.max_iterations = 7;
  EXPECT_DOUBLE_EQ(v.corrector_options().residual_tolerance, 5e-7);
  EXPECT_EQ(v.corrector_options().max_iterations, 7);
  EXPECT_EQ(make_verifier(v, RankOptions{})->name(), "eigen");
}

// Rank report + verification at a solution point x of `problem`.
RankReport verified_report(const Problem& problem, const Vector& x, Corrector& corrector) {
  Matrix J;
  EXPECT_EQ(problem.jacobian(x, J), EvalStatus::ok);
  RankReport r = rank_report(J, RankOptions{});
  verify_null_directions(problem, x, corrector, VerifyOptions{}, r);
  return r;
}

NewtonOptions tight() {
  NewtonOptions o;
  o.residual_tolerance = 1e-12;  // below VerifyOptions::residual_tolerance (1e-9)
  o.max_iterations = 60;         // the double root converges linearly (error halves)
  return o;
}

TEST(VerifyNullDirections, CircleIsACurve) {
  Sphere circle(2);
  Vector x(2);
  x << 0.6, 0.8;
  EigenNewton eigen(tight());
  KinsolNewton kinsol(tight());  // m + 1 == n: the constrained system is square
  for (Corrector* c : {static_cast<Corrector*>(&eigen), static_cast<Corrector*>(&kinsol)}) {
    const RankReport r = verified_report(circle, x, *c);
    EXPECT_EQ(r.nullity, 1);
    EXPECT_EQ(r.verified_dimension, 1) << c->name() << ": " << r.summary();
    ASSERT_EQ(r.direction_verified.size(), 1u);
    EXPECT_TRUE(r.direction_verified[0]);
  }
}

// A known neighbour (the branch's previous point) verifies the direction it lies along by the
// probe's own tests, for the price of one residual; one that lies off the candidate direction
// (drift above drift_ratio 0.1) or off the solution set leaves the probe to run.
TEST(VerifyNullDirections, AKnownNeighbourAlongTheDirectionStandsInForItsProbe) {
  Sphere circle(2);
  const double a = std::atan2(0.8, 0.6);
  const auto on_circle = [](double angle) {
    Vector z(2);
    z << std::cos(angle), std::sin(angle);
    return z;
  };
  const Vector x = on_circle(a);
  Matrix J;
  ASSERT_EQ(circle.jacobian(x, J), EvalStatus::ok);
  EigenNewton eigen(tight());
  struct Case {
    Vector neighbour;
    bool probed;
  };
  // The chord to angle a + t leaves the tangent at x by tan(t / 2) of its length: 0.05 at
  // t = 0.1 (stands in), 0.26 at t = 0.5 (too far off). The third lies 0.01 along the tangent,
  // 5e-5 off the circle (|F| 1e-4 > residual_tolerance 1e-9).
  Vector tangent(2);
  tangent << -0.8, 0.6;
  const Vector off = x + 0.01 * tangent;
  for (const Case& c :
       {Case{on_circle(a + 0.1), false}, Case{on_circle(a - 0.5), true}, Case{off, true}}) {
    RankReport r = rank_report(J, RankOptions{});
    const long residuals = circle.counters().residuals, jacobians = circle.counters().jacobians;
    verify_null_directions(circle, x, eigen, VerifyOptions{}, r, nullptr, &c.neighbour);
    EXPECT_EQ(r.verified_dimension, 1) << r.summary();
    const long used = circle.counters().residuals - residuals;
    if (c.probed) {
      EXPECT_GT(used, 0);  // the probe's residuals (and the neighbour's when it passed drift)
    } else {
      EXPECT_EQ(used, 1);
      EXPECT_EQ(circle.counters().jacobians, jacobians);
    }
  }
}

// The residual of the neighbour, when the caller has it (a branch recorded it), is not
// evaluated again: the neighbour along the tangent then verifies for no evaluation at all. A
// given residual above residual_tolerance refuses the neighbour as an evaluated one would (the
// probe then runs), so the verdict is the same either way.
TEST(VerifyNullDirections, AGivenNeighbourResidualIsNotEvaluatedAgain) {
  Sphere circle(2);
  const double a = std::atan2(0.8, 0.6);
  Vector x(2), neighbour(2);
  x << std::cos(a), std::sin(a);
  neighbour << std::cos(a + 0.1), std::sin(a + 0.1);
  Matrix J;
  ASSERT_EQ(circle.jacobian(x, J), EvalStatus::ok);
  EigenNewton eigen(tight());
  Vector f;
  ASSERT_EQ(circle.residual(neighbour, f), EvalStatus::ok);
  const double known = f.lpNorm<Eigen::Infinity>();
  RankReport r = rank_report(J, RankOptions{});
  long residuals = circle.counters().residuals;
  verify_null_directions(circle, x, eigen, VerifyOptions{}, r, nullptr, &neighbour, known);
  EXPECT_EQ(r.verified_dimension, 1) << r.summary();
  EXPECT_EQ(circle.counters().residuals - residuals, 0);
  // A residual of 1e-3 (above 1e-9) for the same point: refused, so the probe runs and verifies.
  RankReport again = rank_report(J, RankOptions{});
  residuals = circle.counters().residuals;
  verify_null_directions(circle, x, eigen, VerifyOptions{}, again, nullptr, &neighbour, 1e-3);
  EXPECT_EQ(again.verified_dimension, 1) << again.summary();
  EXPECT_GT(circle.counters().residuals - residuals, 0);
}

// The probes' chord steps start on J(x) while it serves (rank_report.cpp, ChordStart). On the
// unit sphere in R^6 at e_0 (5 null directions; each probe steps h along e_i, where
// F = h^2) the exact J(x) = 2 e_0^T corrects every probe alone: no Jacobian. A J(x) of the
// wrong sign (what a Jacobian across a kink can be) moves each chord step outwards, so it
// never pays: the first two probes try it (one residual each), the other three start with a
// fresh Jacobian at once, and every direction still verifies, the answer being judged by F.
TEST(VerifyNullDirections, ProbesStopStartingOnAJacobianAtXThatNeverServes) {
  Sphere sphere(6);
  const Vector x = Vector::Unit(6, 0);
  Matrix exact;
  ASSERT_EQ(sphere.jacobian(x, exact), EvalStatus::ok);
  const Matrix wrong = -exact;
  const auto verify = [&](const Matrix* at_x, long& residuals, long& jacobians) {
    const auto verifier = make_verifier(VerifyOptions{}, RankOptions{});
    RankReport r = rank_report(exact, RankOptions{});
    const long r0 = sphere.counters().residuals, j0 = sphere.counters().jacobians;
    verify_null_directions(sphere, x, *verifier, VerifyOptions{}, r, at_x);
    residuals = sphere.counters().residuals - r0;
    jacobians = sphere.counters().jacobians - j0;
    return r.verified_dimension;
  };
  long res_exact = 0, jac_exact = 0, res_none = 0, jac_none = 0, res_wrong = 0, jac_wrong = 0;
  EXPECT_EQ(verify(&exact, res_exact, jac_exact), 5);
  EXPECT_EQ(jac_exact, 0);
  EXPECT_EQ(verify(nullptr, res_none, jac_none), 5);
  EXPECT_EQ(verify(&wrong, res_wrong, jac_wrong), 5);
  EXPECT_EQ(jac_wrong, jac_none);
  EXPECT_EQ(res_wrong, res_none + 2);  // two refused chord steps, then no more attempts
}

TEST(VerifyNullDirections, SphereIsASurface) {
  Sphere sphere(3);
  Vector x(3);
  x << 0.0, 0.6, 0.8;
  EigenNewton eigen(tight());  // constrained system 2 x 3: needs minimum-norm steps
  const RankReport r = verified_report(sphere, x, eigen);
  EXPECT_EQ(r.nullity, 2);
  EXPECT_EQ(r.verified_dimension, 2) << r.summary();
}

TEST(VerifyNullDirections, DoubleRootAtTheVertexIsACurve) {
  // J(0, 0) = 0: candidate nullity 2. Along e_x the parabola y = x^2 is within h^2 of the
  // stepped point; along e_y the only solutions on the hyperplane y = h are x = +-sqrt(h),
  // ~30 h away, far beyond drift_ratio * h.
  DoubleRootParabola p;
  const Vector x = Vector::Zero(2);
  EigenNewton eigen(tight());
  const RankReport r = verified_report(p, x, eigen);
  EXPECT_EQ(r.rank, 0);
  EXPECT_EQ(r.nullity, 2);
  EXPECT_EQ(r.verified_dimension, 1) << r.summary();
  // The verified direction is the tangent (1, 0), up to sign.
  int verified_column = r.direction_verified[0] ? 0 : 1;
  EXPECT_NEAR(std::abs(r.null_directions(0, verified_column)), 1.0, 1e-6);
}

TEST(VerifyNullDirections, DoubleRootWithMisalignedBasisIsACurve) {
  // At (1, 1) J = 0 again and the SVD basis is (e_x, e_y), but the tangent is (1, 2)/sqrt(5):
  // neither candidate is tangent, stepping along each drifts by 2h resp. h/2. Verification
  // must rotate the basis onto the secants and still find exactly one real direction.
  DoubleRootParabola p;
  const Vector x = Vector::Ones(2);
  EigenNewton eigen(tight());
  KinsolNewton kinsol(tight());
  for (Corrector* c : {static_cast<Corrector*>(&eigen), static_cast<Corrector*>(&kinsol)}) {
    const RankReport r = verified_report(p, x, *c);
    EXPECT_EQ(r.nullity, 2);
    EXPECT_EQ(r.verified_dimension, 1) << c->name() << ": " << r.summary();
    for (int j = 0; j < 2; ++j) {
      if (!r.direction_verified[static_cast<std::size_t>(j)]) continue;
      const Vector tangent = Eigen::Vector2d(1.0, 2.0).normalized();
      // Secants from h = 1e-3 probes: the tangent is recovered to O(h).
      EXPECT_NEAR(std::abs(r.null_directions.col(j).dot(tangent)), 1.0, 1e-2);
    }
  }
}

// At (1, 1) on the double root, a probe starts with |y - x^2| ~ 2e-3 and Newton halves it per
// iteration (F = g^2): reaching ||F|| <= 1e-10 (|g| <= 1e-5) takes about 8 iterations. The
// default verifier (60) verifies the curve; one capped at 3 iterations cannot, so the cap is
// the one VerifyOptions sets.
TEST(VerifyNullDirections, DoubleRootNeedsTheVerifiersIterationBudget) {
  DoubleRootParabola p;
  const Vector x = Vector::Ones(2);
  Matrix J;
  ASSERT_EQ(p.jacobian(x, J), EvalStatus::ok);
  for (const int cap : {60, 3}) {
    VerifyOptions v;
    v.max_iterations = cap;
    RankReport r = rank_report(J, RankOptions{});
    verify_null_directions(p, x, *make_verifier(v, RankOptions{}), v, r);
    EXPECT_EQ(r.verified_dimension, cap == 60 ? 1 : 0) << cap << ": " << r.summary();
  }
}

// One equation g(x) exp(x_2) = 0 in n unknowns: the solution set is g = 0, and where g has
// no root on a hyperplane, Gauss-Newton moves x_2 by -1 per step.
class TimesExp : public Problem {
 public:
  TimesExp(int n, double (*g)(const Vector&)) : n_(n), g_(g) {}
  int num_unknowns() const override { return n_; }
  int num_equations() const override { return 1; }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override {
    r.resize(1);
    r[0] = g_(x) * std::exp(x[1]);
    return EvalStatus::ok;
  }

 private:
  int n_;
  double (*g_)(const Vector&);
};

// verify_null_directions from the origin with the candidate basis (e_1, ..., e_n).
RankReport verified_from_origin(const Problem& p) {
  RankReport r;
  r.null_directions = Matrix::Identity(p.num_unknowns(), p.num_unknowns());
  const VerifyOptions v;
  verify_null_directions(p, Vector::Zero(p.num_unknowns()), *make_verifier(v, RankOptions{}), v, r);
  return r;
}

// F(x) = x_1^2 exp(x_2) = 0: the line x_1 = 0. From the origin, the probe along e_2 starts on
// it (F = 0, no Jacobian); the one along e_1 meets the hyperplane x_1 = +-h, where F = h^2
// exp(x_2) has no root and each Gauss-Newton step moves x_2 by -1 (F / dF/dx_2 = 1). Unbounded,
// that correction "converges" at x_2 = -10 (h^2 e^-10 < 1e-10, h = 1e-3) after 10 Jacobians,
// 1e4 h from the stepped point; the probe's region (|h| / drift_ratio = 1e-2 around x) refuses
// the second Jacobian, at x_2 = -1. Both sides of e_1 in both passes (the second probes only
// e_1 again): 4 Jacobians where there were 40, and the same verdict.
TEST(VerifyNullDirections, AProbeThatWandersOffEndsAtTheEdgeOfItsRegion) {
  const TimesExp p(2, [](const Vector& x) { return x[0] * x[0]; });
  const RankReport r = verified_from_origin(p);
  EXPECT_EQ(r.verified_dimension, 1) << r.summary();
  EXPECT_EQ(p.counters().jacobians, 4);
}

// F(x) = (x_1 - x_3^2) exp(x_2) = 0: the surface x_1 = x_3^2. From the origin with the basis
// (e_1, e_2, e_3): e_2 starts on it (no Jacobian), e_3 lands on it in one Newton step (x_1 =
// h^2, drift h), e_1 wanders off as in the test above (one Jacobian on each side). The second
// pass keeps e_2 and e_3 as they are and probes again only the span of e_1: 1 + 2 + 2
// Jacobians, and the basis returned starts with the two verified directions.
TEST(VerifyNullDirections, TheSecondPassKeepsTheDirectionsThatPassed) {
  const TimesExp p(3, [](const Vector& x) { return x[0] - x[2] * x[2]; });
  const RankReport r = verified_from_origin(p);
  EXPECT_EQ(r.verified_dimension, 2) << r.summary();
  EXPECT_EQ(p.counters().jacobians, 5);
  ASSERT_EQ(r.direction_verified.size(), 3u);
  EXPECT_TRUE(r.direction_verified[0]);
  EXPECT_TRUE(r.direction_verified[1]);
  EXPECT_FALSE(r.direction_verified[2]);
  EXPECT_EQ(r.null_directions.col(0), Vector::Unit(3, 1));
  EXPECT_EQ(r.null_directions.col(1), Vector::Unit(3, 2));
  EXPECT_EQ(r.null_directions.col(2).cwiseAbs(), Vector::Unit(3, 0));
}

TEST(VerifyNullDirections, BoundaryOfAHalfPlaneIsASurface) {
  // At the origin e_x points out of the half-plane x <= 0: the probe at x = +h stalls at
  // F = h^2 = 1e-6, far above the 1e-9 tolerance, so a one-sided verifier rejects it (given
  // alone, no successful probe can rotate it). Solutions exist along -e_x (F = 0 exactly), so
  // probing the other side verifies it, and with e_y the half-plane is a surface up to its
  // boundary.
  HalfPlane p;
  const Vector x = Vector::Zero(2);
  VerifyOptions v;
  RankReport outward;
  outward.null_directions = Vector::Unit(2, 0);
  verify_null_directions(p, x, *make_verifier(v, RankOptions{}), v, outward);
  EXPECT_EQ(outward.verified_dimension, 1) << outward.summary();
  RankReport both;
  both.null_directions = Matrix::Identity(2, 2);
  verify_null_directions(p, x, *make_verifier(v, RankOptions{}), v, both);
  EXPECT_EQ(both.verified_dimension, 2) << both.summary();
}

TEST(RankReportBeside, KinkOnTheBoundaryHidesADirectionThatTheInteriorShows) {
  // At the origin forward differences give J = (1, 0): one candidate, e_y. The family (x <= 0)
  // continues along -e_x; J there is exactly 0 (F = 0 for x < 0), so both directions are
  // candidates and both verify from the origin (e_x on its -h side, F = 0 exactly).
  KinkedHalfPlane p;
  const Vector x = Vector::Zero(2);
  VerifyOptions v;
  Matrix J;
  ASSERT_EQ(p.jacobian(x, J), EvalStatus::ok);
  RankReport at = rank_report(J, RankOptions{});
  EXPECT_EQ(at.nullity, 1);
  RankReport beside = rank_report_beside(p, x, -Vector::Unit(2, 0), v.step, RankOptions{});
  EXPECT_EQ(beside.nullity, 2);
  verify_null_directions(p, x, *make_verifier(v, RankOptions{}), v, beside);
  EXPECT_EQ(beside.verified_dimension, 2) << beside.summary();
  // A direction along which nothing is known gives nothing.
  EXPECT_EQ(rank_report_beside(p, x, Vector::Zero(2), v.step, RankOptions{}).nullity, 0);
}

TEST(VerifyNullDirections, IsolatedRootHasNothingToVerify) {
  Matrix J = Matrix::Identity(2, 2);
  RankReport r = rank_report(J, RankOptions{});
  EigenNewton eigen({});
  Sphere circle(2);  // any problem of the right size: nothing is evaluated
  verify_null_directions(circle, Vector::Zero(2), eigen, VerifyOptions{}, r);
  EXPECT_EQ(r.nullity, 0);
  EXPECT_EQ(r.verified_dimension, 0);
}

}  // namespace
}  // namespace backbone::core
