// The fronts' return map K (problems/exact_bar/front_monodromy.hpp): its tangent against
// differences of the exact map, its structure on the closed-form orbits, and its prediction of
// where a perturbed orbit's fronts are after many periods of the full (nonlinear) march.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/monodromy.hpp"
#include "problems/contact_bar/orbits/tdbem_fronts.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/front_monodromy.hpp"

namespace backbone {
namespace {

using exact_bar::CharacteristicState;
using exact_bar::ExactBarSolution;

bar::BarSetup contact_bar_setup(bar::EndType type = bar::EndType::contact, double gap_back = 0) {
  bar::BarSetup s;
  s.right = {type, 1e-3, gap_back};
  return s;
}

struct Orbit {
  bar::BarSetup setup;
  double period = 0;
  CharacteristicState state;  // at a time the end is free
};

Orbit orbit_of(bar::BarSetup setup, bar::PiecewiseLinear u0, double period) {
  setup.u0 = std::move(u0);
  const ExactBarSolution solution(setup, period);
  const exact_bar::OrbitState start = exact_bar::free_flight_state(solution, period);
  EXPECT_FALSE(std::isnan(start.t0));
  return {setup, period, start.state};
}

std::vector<Orbit> closed_form_orbits() {
  std::vector<Orbit> orbits;
  const bar::BarSetup s = contact_bar_setup();
  for (int J : {1, 2, 3, 4}) {
    const contact_bar::ContactFamily mode(s.material, 1e-3, J);
    for (double f : {1.5, 30.0}) {
      const double e = f * mode.grazing_energy();
      orbits.push_back(orbit_of(s, mode.u0(e), mode.period(e)));
    }
  }
  const contact_bar::ContactFamily mode2(s.material, 1e-3, 2);
  for (double shape : {0.25, 0.6}) {
    const auto m =
        contact_bar::subharmonic_member(s.material, 1e-3, 3 * mode2.grazing_energy(), shape);
    orbits.push_back(orbit_of(s, m.u0, m.period));
  }
  for (double gap_back : {1e-3, 3e-3}) {
    const bar::BarSetup c = contact_bar_setup(bar::EndType::clearance, gap_back);
    const contact_bar::ClearanceMode mode(c.material, 1e-3, gap_back, 2);
    const double e = 4 * mode.back_grazing_energy();
    orbits.push_back(orbit_of(c, mode.u0(e), mode.period(e)));
  }
  return orbits;
}

// The fronts' arrival times at t in the order of `like`'s fronts (A's, then B's), matched by
// nearest start; NaN where none is within 1e-3 tau.
Eigen::VectorXd fronts_at(const ExactBarSolution& sol, double t, const CharacteristicState& like) {
  const CharacteristicState now =
      exact_bar::without_small_jumps(sol.characteristic_state(t), 1e-9, 1.0);
  Eigen::VectorXd out(like.fronts());
  int i = 0;
  for (bool of_a : {true, false}) {
    const auto& want = of_a ? like.a_start : like.b_start;
    const auto& have = of_a ? now.a_start : now.b_start;
    for (std::size_t j = 1; j < want.size(); ++j, ++i) {
      double best = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t k = 1; k < have.size(); ++k)
        if (std::abs(have[k] - want[j]) < 1e-3 &&
            !(std::abs(best - want[j]) <= std::abs(have[k] - want[j])))
          best = have[k];
      out[i] = best;
    }
  }
  return out;
}

// The state with its fronts moved by `shift` (A's, then B's) and its values by `dvalue`.
CharacteristicState moved(CharacteristicState s, const Eigen::VectorXd& shift,
                          const Eigen::VectorXd& dvalue) {
  int i = 0, j = 0;
  for (bool of_a : {true, false}) {
    auto& start = of_a ? s.a_start : s.b_start;
    auto& value = of_a ? s.a_value : s.b_value;
    for (std::size_t k = 1; k < start.size(); ++k) start[k] += shift[i++];
    for (double& v : value) v += dvalue[j++];
  }
  return s;
}

TEST(FrontMonodromy, JordanDefectCountsTheMissingEigenvectors) {
  // Exact Jordan forms, conjugated by a fixed invertible matrix so that the blocks are not
  // visible in the entries; the defect does not change under similarity.
  Eigen::Matrix3d S;
  S << 2, 1, 0, 1, 3, 1, 0, 1, 4;
  auto conjugated = [&](const Eigen::Matrix3d& J) { return Eigen::MatrixXd(S * J * S.inverse()); };
  Eigen::Matrix3d J;
  J << -1, 1, 0, 0, -1, 0, 0, 0, 1;  // a block of size 2 at -1, a 1
  EXPECT_EQ(contact_bar::jordan_defect(conjugated(J)), 1);
  J << -1, 0, 0, 0, -1, 0, 0, 0, 1;  // -1 twice with two eigenvectors
  EXPECT_EQ(contact_bar::jordan_defect(conjugated(J)), 0);
  J << 1, 1, 0, 0, 1, 1, 0, 0, 1;  // one block of size 3
  EXPECT_EQ(contact_bar::jordan_defect(conjugated(J)), 2);
  J << 1, 1, 0, 0, 1, 0, 0, 0, 1;  // +1 three times, two eigenvectors
  EXPECT_EQ(contact_bar::jordan_defect(conjugated(J)), 1);
  // A block split by an error of 1e-10 in one entry (eigenvalues -1 +- 1e-5) is still one.
  J << -1, 1, 0, 1e-10, -1, 0, 0, 0, 1;
  EXPECT_EQ(contact_bar::jordan_defect(conjugated(J)), 1);
  const double c = std::cos(1.0), s = std::sin(1.0);  // a rotation: distinct, on the circle
  J << c, -s, 0, s, c, 0, 0, 0, 1;
  EXPECT_EQ(contact_bar::jordan_defect(conjugated(J)), 0);
}

TEST(FrontMonodromy, TangentMatchesCentralDifferencesOfTheExactMap) {
  // The map is affine while the contact sequence stays the same, so central differences of the
  // plain march (no tangent code) are exact but for round-off: event times carry a few ulps of
  // tau, divided by the step 1e-7 tau (1e-8); 1e-6 leaves room for the closing's division by
  // the end velocity.
  for (const Orbit& o : closed_form_orbits()) {
    const int f = o.state.fronts(), p = o.state.pieces();
    const exact_bar::FrontMonodromy m = exact_bar::front_monodromy(o.setup, o.state, o.period);
    ASSERT_TRUE(m.ok) << m.message;
    const double h = 1e-7;
    const double scale = o.state.a_value.empty() ? 1 : std::abs(o.state.a_value.front()) + 1e-300;
    for (int col = 0; col < f + p; ++col) {
      Eigen::VectorXd shift = Eigen::VectorXd::Zero(f), dvalue = Eigen::VectorXd::Zero(p);
      const double step = col < f ? h : h * scale;
      (col < f ? shift[col] : dvalue[col - f]) = step;
      const ExactBarSolution plus(o.setup, o.period, moved(o.state, shift, dvalue), false);
      const ExactBarSolution minus(o.setup, o.period, moved(o.state, -shift, -dvalue), false);
      const Eigen::VectorXd diff =
          (fronts_at(plus, o.period, o.state) - fronts_at(minus, o.period, o.state)) / (2 * step);
      const Eigen::VectorXd tangent =
          col < f ? Eigen::VectorXd(m.K.col(col)) : Eigen::VectorXd(m.C.col(col - f));
      const double unit = col < f ? 1.0 : 1.0 / scale;
      EXPECT_LT((diff - tangent).cwiseAbs().maxCoeff(), 1e-6 * unit)
          << "period " << o.period << " column " << col;
    }
  }
}

TEST(FrontMonodromy, ClosedFormOrbitsKeepTheStructure) {
  // Exact statements, so round-off bounds: a time shift moves every front alike (K 1 = 1); no
  // front shift reaches a value; the values' map keeps the L2 product (an isometry); the orbit
  // comes back (its fronts and values at T are those at 0).
  for (const Orbit& o : closed_form_orbits()) {
    const exact_bar::FrontMonodromy m = exact_bar::front_monodromy(o.setup, o.state, o.period);
    ASSERT_TRUE(m.ok) << m.message;
    EXPECT_LT(m.time_shift_error, 1e-12);
    EXPECT_EQ(m.value_leak, 0.0);
    EXPECT_LT(m.isometry_error, 1e-12);
    EXPECT_LT(m.return_error, 1e-12);
    // Every multiplier on the unit circle. A Jordan block of size 2 splits by sqrt(ulp).
    const Eigen::VectorXcd multipliers =
        Eigen::EigenSolver<Eigen::MatrixXd>(m.K, false).eigenvalues();
    for (const auto& mu : multipliers) EXPECT_NEAR(std::abs(mu), 1.0, 1e-7);
  }
}

TEST(FrontMonodromy, ModeJHasAJordanBlockAtEachNontrivialJthRootOfUnity) {
  // Mode 1 has one front, so K = [1] (the time shift) whatever its entries' derivation; mode 2
  // traversed twice belongs to the two-parameter subharmonic family of period 2 T, whose
  // direction returns after two periods and not after one: -1. What is asserted beyond these
  // two facts (J = 3, 4, and the Jordan structure) is what the solver computes, checked against
  // the nonlinear march by the next test.
  const bar::BarSetup s = contact_bar_setup();
  for (int J : {1, 2, 3, 4}) {
    const contact_bar::ContactFamily mode(s.material, 1e-3, J);
    const double e = 5 * mode.grazing_energy();
    const Orbit o = orbit_of(s, mode.u0(e), mode.period(e));
    const exact_bar::FrontMonodromy m = exact_bar::front_monodromy(o.setup, o.state, o.period);
    ASSERT_TRUE(m.ok) << m.message;
    EXPECT_EQ(m.K.rows(), 2 * J - 1);
    EXPECT_EQ(contact_bar::jordan_defect(m.K), J - 1);
    // K^J = I + N, N != 0 nilpotent: every eigenvalue a J-th root of unity.
    Eigen::MatrixXd power = Eigen::MatrixXd::Identity(m.K.rows(), m.K.cols());
    for (int k = 0; k < J; ++k) power = power * m.K;
    const Eigen::MatrixXd N = power - Eigen::MatrixXd::Identity(m.K.rows(), m.K.cols());
    EXPECT_LT((N * N).cwiseAbs().maxCoeff(), 1e-12);
    if (J > 1) {
      EXPECT_GT(N.cwiseAbs().maxCoeff(), 0.5);
    } else {
      EXPECT_LT(N.cwiseAbs().maxCoeff(), 1e-12);
    }
  }
}

TEST(FrontMonodromy, PredictsTheFrontsOfThePerturbedMarchOverManyPeriods) {
  // The nonlinear march from a state whose fronts are moved by d (1e-6 tau): after k periods
  // its fronts sit at K^k d while the contact sequence holds (a front shift reaches no value).
  // The map being affine, the two agree to round-off over the perturbation (1e-16 / 1e-6);
  // 1e-7 of the shift leaves a margin for k periods of it. Mode 2's Jordan block makes the
  // fronts drift linearly in k; mode 1's stay put, and so do those of mode 2 in a symmetric
  // clearance, whose -1 is a double multiplier with two eigenvectors.
  const bar::BarSetup s = contact_bar_setup();
  const bar::BarSetup c = contact_bar_setup(bar::EndType::clearance, 1e-3);
  const contact_bar::ClearanceMode clearance(c.material, 1e-3, 1e-3, 2);
  const double ec = 4 * clearance.back_grazing_energy();
  for (int J : {1, 2, -2}) {
    const contact_bar::ContactFamily mode(s.material, 1e-3, std::abs(J));
    const double e = 5 * mode.grazing_energy();
    const Orbit o = J > 0 ? orbit_of(s, mode.u0(e), mode.period(e))
                          : orbit_of(c, clearance.u0(ec), clearance.period(ec));
    EXPECT_EQ(contact_bar::jordan_defect(exact_bar::front_monodromy(o.setup, o.state, o.period).K),
              J == 2 ? 1 : 0);
    const exact_bar::FrontMonodromy m = exact_bar::front_monodromy(o.setup, o.state, o.period);
    ASSERT_TRUE(m.ok) << m.message;
    const int f = o.state.fronts();
    Eigen::VectorXd d(f);
    for (int i = 0; i < f; ++i) d[i] = 1e-6 * (i % 2 == 0 ? 1.0 : -0.5);
    const int periods = 20;
    const ExactBarSolution march(o.setup, periods * o.period,
                                 moved(o.state, d, Eigen::VectorXd::Zero(o.state.pieces())), false);
    const Eigen::VectorXd base =
        fronts_at(ExactBarSolution(o.setup, o.period, o.state, false), 0, o.state);
    Eigen::VectorXd predicted = d;
    double largest = 0;
    for (int k = 1; k <= periods; ++k) {
      predicted = m.K * predicted;
      const Eigen::VectorXd actual = fronts_at(march, k * o.period, o.state) - base;
      EXPECT_LT((actual - predicted).cwiseAbs().maxCoeff(), 1e-7 * predicted.cwiseAbs().maxCoeff())
          << "mode " << J << " period " << k;
      largest = std::max(largest, predicted.cwiseAbs().maxCoeff());
    }
    if (J == 2)
      EXPECT_GT(largest, 5 * 1e-6);  // linear growth along the Jordan chain
    else
      EXPECT_LT(largest, 3e-6);  // bounded: a few times the shift
  }
}

// The state in characteristic form handed to the TD-BEM as u0 and a v0 with jumps
// (exact_bar::with_characteristic_state), read back from its field at once and after it has
// marched 2.3 tau from it: the exact solver's march from the same state is the oracle. Between
// events both are exact for such data, so what is left is round-off (1e-12 relative).
TEST(TdbemFronts, TheTdbemCarriesAStateInCharacteristicFormLikeTheExactSolver) {
  for (const Orbit& o : closed_form_orbits()) {
    const double tau = o.setup.material.travel_time();
    const bar::BarSetup start = exact_bar::with_characteristic_state(o.setup, o.state);
    const ExactBarSolution exact(o.setup, 2.3 * tau, o.state, false);
    for (double t : {0.0, 2.3 * tau}) {
      contact_bar::TdbemMarch march(start, tau / 37.5, contact_bar::ContactMethod::event);
      ASSERT_TRUE(march.advance_to(t));
      const CharacteristicState want = exact_bar::without_small_jumps(
          exact.characteristic_state(t), exact_bar::default_jump_tolerance, tau);
      const CharacteristicState have = exact_bar::without_small_jumps(
          contact_bar::tdbem_characteristic_state(march), exact_bar::default_jump_tolerance, tau);
      ASSERT_EQ(have.a_start.size(), want.a_start.size()) << "t " << t;
      ASSERT_EQ(have.b_start.size(), want.b_start.size()) << "t " << t;
      double scale = 0;
      for (double y : want.a_value) scale = std::max(scale, std::abs(y));
      for (double y : want.b_value) scale = std::max(scale, std::abs(y));
      for (std::size_t i = 0; i < want.a_start.size(); ++i) {
        EXPECT_NEAR(have.a_start[i], want.a_start[i], 1e-12 * tau);
        EXPECT_NEAR(have.a_value[i], want.a_value[i], 1e-12 * scale);
      }
      for (std::size_t i = 0; i < want.b_start.size(); ++i) {
        EXPECT_NEAR(have.b_start[i], want.b_start[i], 1e-12 * tau);
        EXPECT_NEAR(have.b_value[i], want.b_value[i], 1e-12 * scale);
      }
    }
  }
}

// K by central differences of the TD-BEM's march (no tangent, no exact solver but for the
// choice of t0) against K from the exact solver's tangent, on and off the step grid (tau / dt
// 40 and 40.5). The fronts' positions carry the round-off of an event's root and of the march's
// times, about 1e-15 tau, divided by the step 1e-6 tau: 1e-9 (1.4e-10 measured); 1e-8 leaves
// room for the closing's division by the end velocity.
TEST(TdbemFronts, TheTdbemsKMatchesTheExactSolversTangent) {
  for (const Orbit& o : closed_form_orbits()) {
    const double tau = o.setup.material.travel_time();
    const ExactBarSolution solution(o.setup, o.period);
    const exact_bar::OrbitState start = exact_bar::free_flight_state(solution, o.period);
    const exact_bar::FrontMonodromy m = exact_bar::front_monodromy(o.setup, start.state, o.period);
    ASSERT_TRUE(m.ok) << m.message;
    for (double steps : {40.0, 40.5}) {
      const contact_bar::TdbemFronts t =
          contact_bar::tdbem_front_monodromy(o.setup, start.t0, o.period, tau / steps);
      ASSERT_TRUE(t.ok) << t.message << " period " << o.period;
      ASSERT_EQ(t.K.rows(), m.K.rows());
      EXPECT_LT((t.K - m.K).cwiseAbs().maxCoeff(), 1e-8) << "period " << o.period;
      // Off kinks the map is affine: the one-sided differences agree to the same round-off.
      EXPECT_LT(t.kink, 2e-8) << "period " << o.period;
    }
  }
}

// The continuum's grazing limit (shape 1: one contact phase and one grazing instant) is a kink
// of the period map: a front moved one way makes the grazing a contact, the other way not, and
// the one-sided differences of the TD-BEM's K disagree by order 1 (1.0 measured). An interior
// member's map is affine around it: the two agree to round-off over the step.
// The multipliers' distance pairs the eigenvalues one to one at the smallest largest gap: for
// {0.5, 0} against {0.4, 1} that is 0.5 (0.5 with 1, 0 with 0.4), where taking each nearest
// in turn leaves 0 with 1. Exact in binary: diagonal matrices, eigenvalues their entries.
TEST(TdbemFronts, TheMultipliersDistanceIsTheBottleneckPairing) {
  Eigen::MatrixXd a = Eigen::Vector2d(0.5, 0.0).asDiagonal();
  Eigen::MatrixXd b = Eigen::Vector2d(0.4, 1.0).asDiagonal();
  EXPECT_DOUBLE_EQ(contact_bar::multiplier_distance(a, b), 0.5);
  EXPECT_DOUBLE_EQ(contact_bar::multiplier_distance(b, a), 0.5);
  // A rotation by 90 degrees (eigenvalues +-i) twice against the identity twice: sqrt 2.
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(4, 4);
  r(0, 1) = -1, r(1, 0) = 1, r(2, 2) = 1, r(3, 3) = 1;
  EXPECT_NEAR(contact_bar::multiplier_distance(r, Eigen::MatrixXd::Identity(4, 4)), std::sqrt(2.0),
              1e-15);
  EXPECT_EQ(contact_bar::multiplier_distance(a, a), 0);
  EXPECT_TRUE(std::isinf(contact_bar::multiplier_distance(a, r)));
}

TEST(TdbemFronts, TheOneSidedDifferencesFindTheContinuumsGrazingKink) {
  const bar::BarSetup s = contact_bar_setup();
  const contact_bar::ContactFamily mode2(s.material, 1e-3, 2);
  const double energy = 3 * mode2.grazing_energy(), tau = s.material.travel_time();
  for (double shape : {0.6, 1.0}) {
    const auto m = contact_bar::subharmonic_member(s.material, 1e-3, energy, shape);
    bar::BarSetup setup = s;
    setup.u0 = m.u0;
    const ExactBarSolution solution(setup, m.period);
    const exact_bar::OrbitState start = exact_bar::free_flight_state(solution, m.period);
    const contact_bar::TdbemFronts t =
        contact_bar::tdbem_front_monodromy(setup, start.t0, m.period, tau / 40.5);
    ASSERT_TRUE(t.ok) << t.message;
    if (shape < 1) {
      EXPECT_LT(t.kink, 2e-8);
    } else {
      EXPECT_GT(t.kink, 0.1);
    }
  }
}

}  // namespace
}  // namespace backbone
