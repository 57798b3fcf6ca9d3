// analyse_monodromy on matrices whose eigenvalues are known exactly: the classification, the
// trivial multipliers, the test functions and the conservative structure checks.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/stability/floquet.hpp"

namespace core = backbone::core;

namespace {

core::Matrix rotation(double angle) {
  core::Matrix R(2, 2);
  R << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  return R;
}

// A similarity by a fixed well-conditioned matrix: the eigenvalues stay, the matrix is not
// diagonal (the solver is exercised, not read off).
core::Matrix conjugated(const core::Matrix& D) {
  core::Matrix P = core::Matrix::Identity(D.rows(), D.cols());
  for (Eigen::Index i = 0; i + 1 < D.rows(); ++i) P(i, i + 1) = 0.5;
  return P * D * P.inverse();
}

// Eigenvalues of 2 x 2 and 4 x 4 matrices of O(1) entries come out within a few ulps times the
// condition of the similarity (below 10): 1e-12 is far from both that and any decision here.
constexpr double exact = 1e-12;

}  // namespace

TEST(Floquet, DissipativeForcedOrbitIsStableInsideTheCircle) {
  const core::Floquet f = core::analyse_monodromy(
      conjugated(core::Vector::LinSpaced(2, 0.5, 0.25).asDiagonal()), {0, false}, {});
  EXPECT_EQ(f.stable, 1);
  EXPECT_EQ(f.unstable, 0);
  EXPECT_NEAR(f.max_modulus, 0.5, exact);
  EXPECT_NEAR(f.determinant, 0.125, exact);
  EXPECT_TRUE(std::isnan(f.pairing_error));  // not a conservative problem
  EXPECT_NEAR(f.period_doubling_test, 1.5 * 1.25, exact);
  EXPECT_NEAR(f.fold_test, -0.5 * -0.75, exact);
}

TEST(Floquet, RealMultiplierBelowMinusOneCountsAsPeriodDoublingSide) {
  core::Vector d(2);
  d << -2.0, -0.25;
  const core::Floquet f = core::analyse_monodromy(conjugated(d.asDiagonal()), {0, false}, {});
  EXPECT_EQ(f.stable, 0);
  EXPECT_EQ(f.unstable, 1);
  EXPECT_EQ(f.outside.real_negative, 1);
  EXPECT_EQ(f.outside.real_positive, 0);
  // (mu + 1) / max(1, |mu|): (-1 / 2) (0.75): negative beyond -1, positive before.
  EXPECT_NEAR(f.period_doubling_test, -0.5 * 0.75, exact);
  EXPECT_NEAR(f.multipliers[0].real(), -2.0, exact);  // by decreasing modulus
}

TEST(Floquet, ComplexPairOutsideTheCircleIsATorusSide) {
  core::Matrix M = core::Matrix::Zero(2, 2);
  M = 1.1 * rotation(0.7);
  const core::Floquet f = core::analyse_monodromy(M, {0, false}, {});
  EXPECT_EQ(f.unstable, 2);
  EXPECT_EQ(f.outside.complex, 2);
  EXPECT_NEAR(f.max_modulus, 1.1, exact);
  // A complex pair keeps both products positive.
  EXPECT_GT(f.period_doubling_test, 0);
  EXPECT_GT(f.fold_test, 0);
}

TEST(Floquet, AutonomousOrbitSetsItsTimeShiftMultiplierApart) {
  core::Vector d(3);
  d << 1.0, 3.0, 0.2;
  const core::Floquet f = core::analyse_monodromy(conjugated(d.asDiagonal()), {1, false}, {});
  EXPECT_EQ(f.unstable, 1);
  EXPECT_NEAR(f.max_modulus, 3.0, exact);
  EXPECT_NEAR(f.trivial_distance, 0.0, exact);
  int trivial = 0;
  for (std::size_t i = 0; i < f.multipliers.size(); ++i)
    if (f.trivial[i]) {
      ++trivial;
      EXPECT_NEAR(f.multipliers[i].real(), 1.0, exact);
    }
  EXPECT_EQ(trivial, 1);
}

TEST(Floquet, ConservativeOrbitOnTheCircleIsStableWithItsStructureChecked) {
  // A Jordan block at +1 (time shift, energy) beside a rotation: symplectic, neutrally stable.
  core::Matrix M = core::Matrix::Zero(4, 4);
  M.topLeftCorner(2, 2) << 1.0, 0.3, 0.0, 1.0;
  M.bottomRightCorner(2, 2) = rotation(2.0);
  const core::Floquet f = core::analyse_monodromy(conjugated(M), {2, true}, {});
  EXPECT_EQ(f.stable, 1);
  EXPECT_EQ(f.unstable, 0);
  EXPECT_NEAR(f.determinant, 1.0, exact);
  // An exact Jordan block's eigenvalues carry errors of sqrt(eps * 0.3) ~ 1e-8.
  EXPECT_LT(f.trivial_distance, 1e-7);
  EXPECT_LT(f.pairing_error, 1e-7);
  EXPECT_NEAR(f.max_modulus, 1.0, exact);
}

TEST(Floquet, ConservativePairOffTheCircleIsUnstableAndPaired) {
  core::Matrix M = core::Matrix::Zero(4, 4);
  M.topLeftCorner(2, 2) = core::Matrix::Identity(2, 2);
  M(2, 2) = 4.0;
  M(3, 3) = 0.25;
  const core::Floquet f = core::analyse_monodromy(conjugated(M), {2, true}, {});
  EXPECT_EQ(f.stable, 0);
  EXPECT_EQ(f.outside.real_positive, 1);
  EXPECT_NEAR(f.pairing_error, 0.0, exact);
}

TEST(Floquet, TrivialMultipliersFarFromOneLeaveTheStabilityUndecided) {
  core::Vector d(2);
  d << 0.9, 0.5;  // an autonomous orbit must have +1: the nearest is 0.1 away
  const core::Floquet f = core::analyse_monodromy(d.asDiagonal().toDenseMatrix(), {1, false}, {});
  EXPECT_EQ(f.stable, -1);
  EXPECT_NEAR(f.trivial_distance, 0.1, exact);
}

TEST(Floquet, NonFiniteMonodromyIsUndecided) {
  core::Matrix M = core::Matrix::Identity(2, 2);
  M(0, 1) = std::numeric_limits<double>::quiet_NaN();
  const core::Floquet f = core::analyse_monodromy(M, {0, false}, {});
  EXPECT_EQ(f.stable, -1);
  EXPECT_TRUE(std::isnan(f.max_modulus));
  EXPECT_EQ(f.multipliers.size(), 2u);
}

TEST(Floquet, OptionsOutsideTheirRangeNameTheirKey) {
  core::FloquetOptions o;
  o.tolerance = 0;
  try {
    o.validate();
    FAIL() << "a zero tolerance was accepted";
  } catch (const std::exception& e) {
    EXPECT_EQ(std::string(e.what()).rfind("floquet_tolerance:", 0), 0u) << e.what();
  }
  o = {};
  o.trivial_tolerance = 0.7;
  EXPECT_THROW(o.validate(), std::exception);
}
