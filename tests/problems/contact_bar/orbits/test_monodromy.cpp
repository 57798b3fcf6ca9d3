// The contact bar's full-state monodromy (orbits/monodromy.hpp) against exact oracles: the
// fixed-free bar without contact returns every state after 4L/c and reverses it after 2L/c
// (d'Alembert: the fixed-free bar's period is 4L/c for every initial state, and u(t + 2L/c) =
// -u(t)), and a piecewise-linear state on the grid is held exactly by the representation, so M
// is I and -I. Against its own structure on mode 1: multipliers on the unit circle, the trivial
// pair at +1 (README.md, section 'Stability').
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include "core/errors.hpp"
#include "core/stability/floquet.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/monodromy.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "tests/problems/contact_bar/paper_setup.hpp"

namespace {

using namespace backbone;

TEST(ContactBarMonodromy, FreeBarReturnsEveryStateAfterFourTransits) {
  bar::BarSetup setup = test_support::paper_setup();
  setup.right = {bar::EndType::free, 0};
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  contact_bar::OrbitOptions o;
  o.elements = 10;
  o.steps_per_period = 2;  // the map's dt is then courant dx / c
  const contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
  core::Vector x = core::Vector::Zero(o.elements + 1);
  for (int i = 0; i < o.elements; ++i) x[i] = 1e-3 * std::sin(0.7 * (i + 1));
  const int n = o.elements;
  for (double transits : {4.0, 2.0}) {
    x[orbit.period_index()] = transits;  // L / c = 1
    const double sign = transits == 4.0 ? 1.0 : -1.0;
    double previous = 0;
    for (double courant : {1.0, 0.5, 0.25, 0.125}) {
      contact_bar::MonodromyOptions mo;
      mo.courant = courant;
      core::Matrix M;
      ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, mo, M), core::EvalStatus::ok);
      const core::Matrix error = M - sign * core::Matrix::Identity(M.rows(), M.cols());
      // The u columns: differences of an affine map the march holds exactly, round-off of the
      // march (1e-16 of the state) over the step (1e-6 of it) times the v rows' c / dx: 1e-8
      // leaves a factor of 100.
      EXPECT_LE(error.leftCols(n).lpNorm<Eigen::Infinity>(), 1e-8) << "T " << transits;
      // The v columns: second order in c dt / dx (the header): each halving divides the error by
      // 4, asserted as at least 3.5 (measured 0.464, 0.116, 0.029, 0.0073 at T = 4).
      const double v_error = error.rightCols(n).lpNorm<Eigen::Infinity>();
      EXPECT_LE(v_error, 0.5 * courant * courant) << "T " << transits << " courant " << courant;
      if (previous > 0) {
        EXPECT_LE(v_error, previous / 3.5) << "courant " << courant;
      }
      previous = v_error;
    }
  }
}

TEST(ContactBarMonodromy, ModeOnesMultipliersLieOnTheUnitCircleWithTheTrivialPairAtOne) {
  const bar::BarSetup setup = test_support::paper_setup();
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  for (int n : {20, 40}) {
    contact_bar::OrbitOptions o;
    o.elements = n;
    contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
    contact_bar::MonodromyOptions grid;
    grid.representation = contact_bar::MonodromyOptions::Representation::grid;
    orbit.set_monodromy_options(grid);
    const core::Vector x = orbit.contact_family_guess(1, 1.5);  // exact on the grid
    core::Matrix M;
    ASSERT_EQ(orbit.monodromy(x, M), core::EvalStatus::ok);
    const core::Floquet f = core::analyse_monodromy(M, orbit.floquet_structure(), {});
    // The wave equation's spectrum lies on the unit circle. The projection of the state at T
    // onto the grid dissipates (the smallest |mu| is 0.45 at N = 20 and 40) and moves the
    // largest by at most 2e-3 beyond it at N = 20 to 80 (README.md, 'Stability'): none may lie
    // beyond 1 + 1e-2, which a growth of the representation itself would break.
    EXPECT_LE(f.max_modulus, 1 + 1e-2) << "N = " << n;
    // The trivial pair (a Jordan block at +1) moves by the square root of M's error. From the
    // tangent: measured 1.2e-5 and 5.0e-6 here (central differences, whose error is linear in
    // their step where fronts move: 1.3e-4 to 2.3e-4); 1e-4 allows M an error of 1e-8.
    EXPECT_LE(f.trivial_distance, 1e-4) << "N = " << n;
  }
}

// The cost is bounded before any simulation: a subharmonic member a hair from its grazing limit
// (shape 1e-7: its last knot 1e-7 D L from the end, an interval far under L / (64 N)) is refused
// at once, where its time step (c dt <= dx / 32) would take some 1e8 steps per simulation. The
// member at shape 0.3 on the same chart has its monodromy.
TEST(ContactBarMonodromy, AGridWithAHairlineIntervalIsRefusedBeforeAnySimulation) {
  const bar::BarSetup setup = test_support::paper_setup();
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  contact_bar::OrbitOptions o;
  o.elements = 20;
  o.free_knots = 2;
  o.start_on_wall = true;
  const double energy = 1e-3;
  const contact_bar::SubharmonicMember member =
      contact_bar::subharmonic_member(setup.material, setup.right.gap, energy, 0.3);
  o.knot_nodes = contact_bar::nearest_knot_nodes(o.elements, 1.0, {member.kinks[0]});
  o.knot_nodes.push_back(o.elements - 1);
  const contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
  contact_bar::MonodromyOptions mo;
  core::Matrix M;
  EXPECT_EQ(contact_bar::full_state_monodromy(orbit, orbit.subharmonic_guess(energy, 1e-7), mo, M),
            core::EvalStatus::failed);
  EXPECT_EQ(contact_bar::full_state_monodromy(orbit, orbit.subharmonic_guess(energy, 0.3), mo, M),
            core::EvalStatus::ok);
}

// A snapshot on a given node grid (SnapshotRequest::nodes) is the uniform one when the grid is
// uniform, for both solvers that take one; on a graded grid the projections of v still sum to
// int_0^L v dx (the hats are a partition of unity), the same number on every grid.
TEST(ContactBarMonodromy, SnapshotsOnAnyNodeGrid) {
  bar::BarSetup setup = test_support::paper_setup();
  setup.u0 = bar::PiecewiseLinear({0.0, 0.37, 1.0}, {0.0, -3e-3, 1e-3});
  setup.v0 = bar::PiecewiseLinear({0.0, 0.6, 1.0}, {0.0, 2e-3, -1e-3});
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  const exact_bar::ExactBarSolver exact;
  std::vector<double> uniform, graded;
  for (int i = 0; i <= 8; ++i) {
    uniform.push_back(i / 8.0);
    graded.push_back(std::pow(i / 8.0, 1.5));
  }
  for (const bar::BarSolver* solver :
       {static_cast<const bar::BarSolver*>(&tdbem), static_cast<const bar::BarSolver*>(&exact)}) {
    bar::SnapshotRequest r;
    r.dt = 1e-3;
    r.elements = 8;
    r.nodal_u = r.projected_v = true;
    const bar::FieldSnapshot plain = solver->snapshot(setup, 2.7, r);
    r.nodes = uniform;
    const bar::FieldSnapshot same = solver->snapshot(setup, 2.7, r);
    r.nodes = graded;
    const bar::FieldSnapshot other = solver->snapshot(setup, 2.7, r);
    ASSERT_TRUE(plain.ok && same.ok && other.ok) << solver->name();
    double total_plain = 0, total_other = 0;
    for (std::size_t i = 0; i < plain.u.size(); ++i) {
      // Round-off of the same sums taken over the same pieces.
      EXPECT_NEAR(same.u[i], plain.u[i], 1e-17) << solver->name();
      EXPECT_NEAR(same.v_projected[i], plain.v_projected[i], 1e-17) << solver->name();
      total_plain += plain.v_projected[i];
      total_other += other.v_projected[i];
    }
    EXPECT_NEAR(total_other, total_plain, 1e-17) << solver->name();
    EXPECT_EQ(other.x, graded);
  }
}

// The independent check: the exact characteristics solver builds the same map by its own route
// (no time step), and its largest multipliers on mode 1 agree with the TD-BEM's to the
// TD-BEM's error in the v columns (0.46 (c dt / dx)^2 = 4.5e-4 at c dt / dx = 1/32; measured
// 1.5e-5 to 6e-5 on modes 1 and 2).
TEST(ContactBarMonodromy, TheExactSolversMultipliersAgreeWithTheTdbems) {
  const bar::BarSetup setup = test_support::paper_setup();
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  const exact_bar::ExactBarSolver exact;
  contact_bar::OrbitOptions o;
  o.elements = 20;
  contact_bar::ContactBarOrbitProblem by_tdbem(setup, tdbem, o), by_exact(setup, exact, o);
  contact_bar::MonodromyOptions grid;
  grid.representation = contact_bar::MonodromyOptions::Representation::grid;
  by_tdbem.set_monodromy_options(grid);
  by_exact.set_monodromy_options(grid);
  const core::Vector x = by_tdbem.contact_family_guess(1, 2.0);
  core::Matrix a, b;
  ASSERT_EQ(by_tdbem.monodromy(x, a), core::EvalStatus::ok);
  ASSERT_EQ(by_exact.monodromy(x, b), core::EvalStatus::ok);
  const core::Floquet fa = core::analyse_monodromy(a, by_tdbem.floquet_structure(), {});
  const core::Floquet fb = core::analyse_monodromy(b, by_exact.floquet_structure(), {});
  // Each of the six largest against its nearest (a pair of nearly equal modulus may come in
  // either order).
  for (std::size_t i = 0; i < 6; ++i) {
    double nearest = 1e300;
    for (const auto& mu : fb.multipliers)
      nearest = std::min(nearest, std::abs(fa.multipliers[i] - mu));
    EXPECT_LT(nearest, 1e-3) << i << ": " << fa.multipliers[i];
  }
}

// The check without a representation (monodromy.hpp, perturbation_growth): a random
// perturbation of 1e-6 of the closed-form orbits (exact) of modes 1 and 2, simulated by the
// exact solver for 1000 periods. Mode 1 stays within a few times its initial size (measured
// at most 1.8; a multiplier of modulus 1.002 in an excited direction would reach 7.4). Mode 2
// may drift linearly in k along its Jordan block at -1, not exponentially: from the last sample
// k_h <= 500 (366) to k = 1000 the distance grows like k^p with p under 1.5 (linear: 1, measured
// 0.996 to 1.006; |mu| = 1.003 in an excited direction: 1.9), and it stays far below the
// 1.09^1000 of the projected monodromy's multiplier (README.md, 'Stability').
TEST(ContactBarMonodromy, PerturbationsOfModesOneAndTwoDoNotGrowExponentially) {
  bar::BarSetup setup = test_support::paper_setup();
  for (int mode : {1, 2}) {
    const contact_bar::ContactFamily family(setup.material, setup.right.gap, mode);
    for (double factor : {2.0, 300.0}) {
      const double energy = factor * family.grazing_energy();
      setup.u0 = family.u0(energy);
      // The draw and its opposite (a negative size) alike.
      const double size = factor == 2.0 ? 1e-6 : -1e-6;
      const contact_bar::PerturbationGrowth g =
          contact_bar::perturbation_growth(setup, family.period(energy), 1000, size, 40, 7);
      ASSERT_TRUE(g.ok);
      if (mode == 1) {
        EXPECT_LT(g.largest, 5) << "E/E_graze " << factor;
        continue;
      }
      int half = 1;
      double at_half = 0;
      for (const auto& [k, d] : g.history)
        if (k <= 500) half = k, at_half = std::max(at_half, d);
      EXPECT_LT(std::log(g.largest / at_half) / std::log(1000.0 / half), 1.5)
          << "E/E_graze " << factor;
      EXPECT_LT(g.largest, 1e3) << "E/E_graze " << factor;
    }
  }
}

// The draw and its opposite are exact opposites away from a wall (monodromy.hpp,
// perturbed_setup): every value and every knot's move the same with the other sign, so the two
// perturbed states average to the orbit's. Here with two knots of u0 2e-6 L apart, where a knot
// may move by a quarter of its intervals only: each knot's room is the orbit's, not one its
// neighbour's move has changed. Away from the knots (1e-6 L, the largest move) the average
// leaves only the second order of the moves, a^2 of 1e-6 (a value at a moved knot over its
// interval, ~1e-12 of the amplitude); a first-order mismatch of a clamped move is ~1e-7.
TEST(ContactBarMonodromy, ThePerturbationAndItsOppositeAreExactOpposites) {
  bar::BarSetup setup = test_support::paper_setup();
  const std::vector<double> knots{0.0, 0.3, 0.3 + 2e-6, 0.7, 1.0};
  setup.u0 = bar::PiecewiseLinear(knots, {0.0, -2e-3, -2.1e-3, -5e-3, -8e-3});
  setup.v0 = bar::PiecewiseLinear({0.0, 0.4, 1.0}, {0.0, 0.01, -0.02});
  for (unsigned seed : {1u, 7u, 11u}) {
    const auto plus = contact_bar::perturbed_setup(setup, 1e-6, 40, seed);
    const auto minus = contact_bar::perturbed_setup(setup, -1e-6, 40, seed);
    ASSERT_TRUE(plus && minus);
    double largest_draw = 0, largest_mismatch = 0;
    for (int i = 0; i <= 20000; ++i) {
      const double x = i / 20000.0;
      if (std::any_of(knots.begin(), knots.end(),
                      [&](double k) { return std::abs(x - k) < 1e-6; }) ||
          std::abs(x - 0.4) < 1e-6)
        continue;
      largest_draw = std::max(largest_draw, std::abs(plus->u0(x) - setup.u0(x)));
      largest_mismatch =
          std::max({largest_mismatch, std::abs(plus->u0(x) + minus->u0(x) - 2 * setup.u0(x)),
                    std::abs(plus->v0(x) + minus->v0(x) - 2 * setup.v0(x))});
    }
    EXPECT_GT(largest_draw, 1e-9) << seed;  // a draw of 1e-6 of the amplitude 8e-3
    EXPECT_LT(largest_mismatch, 1e-10 * 8e-3) << seed;
  }
}

// The march's tangent (solver/tdbem.hpp, 'Tangent') against differences of the same march at
// the same time step.
// - Where no front's characteristic crosses a node within the step, the map is affine and the
//   differences carry only the march's round-off (1e-16 of the state) over the step (1e-6 of
//   it) times the v rows' c / dx: 1e-8 of |M| leaves a factor of 10 (the free bar, mode 2 and a
//   perturbed mode 1 at 10 intervals; measured 1.2e-9 to 7e-9 of |M|).
// - Mode 1's closed form has fronts that move with the closing, and a front moved by w changes
//   the projection of v by w jump psi + w^2 jump psi' / 2: the differences carry an error linear
//   in the step (4.8e-6 of |M| at the default step, 1.48e-6 in one row of the projection), and
//   divided by 10 with the step they must come 10 times closer to the tangent (8 asserted).
// - mode 1's end turns at T: u(L, T) is V-shaped in the phase (+-2/3 at 1.5 g0), and the
//   tangent's readout on that moving knot takes the mean of the sides, as central differences.
TEST(ContactBarMonodromy, TheTangentIsTheMarchsDerivative) {
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  struct Case {
    const char* name;
    bool free_end;
    int mode;
    double amplitude, period, wiggle;
    bool fronts_move;
  };
  for (const Case& c : {Case{"free bar", true, 1, 1.5, 3.3, 0.0, false},
                        Case{"mode 1", false, 1, 1.5, 0.0, 0.0, true},
                        Case{"mode 1 shape", false, 1, 2.0, 0.0, 0.05, false},
                        Case{"mode 2", false, 2, 1.5, 0.0, 0.0, false}}) {
    bar::BarSetup setup = test_support::paper_setup();
    if (c.free_end) setup.right = {bar::EndType::free, 0};
    contact_bar::OrbitOptions o;
    o.elements = 10;
    const int n = o.elements;
    const contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
    core::Vector x = c.free_end ? core::Vector(core::Vector::Zero(n + 1))
                                : orbit.contact_family_guess(c.mode, c.amplitude);
    const double wiggle = c.free_end ? 1e-3 : c.wiggle * std::abs(x[n - 1]);
    for (int i = 0; i < n; ++i) x[i] += wiggle * std::sin(0.7 * (i + 1));
    if (c.period > 0) x[orbit.period_index()] = c.period;
    contact_bar::MonodromyOptions by_tangent, by_differences, by_smaller_step;
    by_tangent.derivatives = contact_bar::MonodromyOptions::Derivatives::tangent;
    by_differences.derivatives = contact_bar::MonodromyOptions::Derivatives::differences;
    by_smaller_step.derivatives = contact_bar::MonodromyOptions::Derivatives::differences;
    by_smaller_step.relative_step = by_differences.relative_step / 10;
    core::Matrix M, D, D_small;
    ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, by_tangent, M), core::EvalStatus::ok);
    ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, by_differences, D), core::EvalStatus::ok);
    const double scale = M.lpNorm<Eigen::Infinity>();
    const double error = (M - D).lpNorm<Eigen::Infinity>() / scale;
    if (!c.fronts_move) {
      EXPECT_LE(error, 1e-8) << c.name;
      continue;
    }
    ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, by_smaller_step, D_small),
              core::EvalStatus::ok);
    const double smaller = (M - D_small).lpNorm<Eigen::Infinity>() / scale;
    EXPECT_GT(error, 1e-7) << c.name << ": no front moved, the case tests nothing";
    EXPECT_LE(smaller, error / 8) << c.name;
  }
}

// Where the march meets a contact decision on a kink of its map (here the end grazes the wall at
// 2.0125 L/c: a perturbation of v at the end's node of one sign makes it touch, of the other
// not), the tangent says so (tangent_on_kink), and is the side of the march's own decisions:
// the projected v's derivative in that direction equals one of the one-sided differences (they
// differ by 2.8 of the column's largest entry, at every step from 1e-9 to 1e-13; the tangent is
// within 6.6e-8 of the forward one at the step 1e-9, the differences' round-off: 1e-5
// asserted). Central differences take the mean of the sides.
TEST(ContactBarMonodromy, AtAKinkTheTangentIsOneSidesDerivative) {
  const bar::BarSetup setup = test_support::paper_setup();
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  const int n = 80;
  contact_bar::OrbitOptions o;
  o.elements = n;
  const contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
  core::Vector x = orbit.contact_family_guess(1, 2.0);
  for (int i = 0; i < n; ++i) x[i] += 0.05 * std::abs(x[n - 1]) * std::sin(0.7 * (i + 1));
  const std::vector<double> nodes = contact_bar::full_state_nodes(orbit, x, 0);
  const core::Vector s = contact_bar::full_state(orbit, x, nodes);
  const double T = x[orbit.period_index()];
  const double dt = contact_bar::full_state_time_step(orbit, T, nodes, 1.0 / 32);
  const auto march = [&](double dv) {
    bar::BarSetup b = setup;
    std::vector<double> u(nodes.size()), v(nodes.size());
    for (int i = 1; i <= n; ++i) u[static_cast<std::size_t>(i)] = s[i - 1];
    v.back() = dv;  // v at the end's node
    b.u0 = bar::PiecewiseLinear(nodes, u);
    b.v0 = bar::PiecewiseLinear(nodes, v);
    contact_bar::TdbemMarch m(b, dt, contact_bar::ContactMethod::event, {nodes, true});
    EXPECT_TRUE(m.advance_to(T));
    return m;
  };
  const contact_bar::TdbemMarch base = march(0);
  EXPECT_TRUE(base.tangent_on_kink());
  const Eigen::VectorXd tangent = base.tangent_projected_velocity(nodes).col(2 * n - 1);
  const double h = 1e-9;
  const std::vector<double> f0 = base.projected_velocity(nodes);
  const std::vector<double> fp = march(h).projected_velocity(nodes);
  const std::vector<double> fm = march(-h).projected_velocity(nodes);
  Eigen::VectorXd forward(n + 1), backward(n + 1);
  for (int i = 0; i <= n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    forward[i] = (fp[k] - f0[k]) / h;
    backward[i] = (f0[k] - fm[k]) / h;
  }
  const double scale = forward.lpNorm<Eigen::Infinity>();
  EXPECT_GT((forward - backward).lpNorm<Eigen::Infinity>(), 0.1 * scale) << "no kink";
  EXPECT_LE(std::min((forward - tangent).lpNorm<Eigen::Infinity>(),
                     (backward - tangent).lpNorm<Eigen::Infinity>()),
            1e-5 * scale);
}
// Mode 1's end turns at T, so a traced orbit's readout falls a round-off before or after the
// kink's arrival (1.1e-11 and 1.6e-9 steps measured at 40 and 80 intervals). The tangent puts a
// kink that close on the readout, both when it has arrived and when it is still pending, so the
// monodromy does not depend on which: the closed forms at N = 20 and 40 with T moved by
// +-1e-13 of itself agree with central differences to their error linear in the step (at most
// 3.3e-5 of |M| over these amplitudes; without the pending kink's half the gap is 0.5 to 0.7).
TEST(ContactBarMonodromy, AKinkARoundOffFromTheReadoutIsOnIt) {
  const bar::BarSetup setup = test_support::paper_setup();
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  for (int n : {20, 40}) {
    contact_bar::OrbitOptions o;
    o.elements = n;
    const contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
    for (double amplitude : {1.05, 1.55, 2.55})
      for (double shift : {-1e-13, 1e-13}) {
        core::Vector x = orbit.contact_family_guess(1, amplitude);
        x[orbit.period_index()] *= 1 + shift;
        contact_bar::MonodromyOptions by_differences;
        by_differences.derivatives = contact_bar::MonodromyOptions::Derivatives::differences;
        core::Matrix M, D;
        ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, {}, M), core::EvalStatus::ok);
        ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, by_differences, D),
                  core::EvalStatus::ok);
        EXPECT_LE((M - D).lpNorm<Eigen::Infinity>(), 1e-4 * D.lpNorm<Eigen::Infinity>())
            << "N " << n << " amplitude " << amplitude << " shift " << shift;
      }
  }
}

// The tangent's rarer branches against differences of the same march (the criterion of
// TheTangentIsTheMarchsDerivative: no front moves in these cases, measured as a tenth of the step
// leaving the gap as it is, so the differences' error is their round-off, 1e-16 of the state over
// the step's 1e-6 of it times the v rows' c / dx and the growth of |M| over long horizons,
// measured 2.1e-8 of |M| in both: 1e-7 asserted):
// - a clearance end (walls 0.5 g0 either side) that closes on both walls within the period;
// - a contact end over 41.7 L/c, long enough for the fixed end's mean strain to move the gauge
//   (regauge() shifts Q of both ends, and with it their tangents).
// Each case checks that it reaches the branch it is for.
TEST(ContactBarMonodromy, TheTangentFollowsTheBackWallAndTheGauge) {
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  struct Case {
    const char* name;
    bool clearance;
    double period;
  };
  for (const Case& c : {Case{"clearance", true, 3.0}, Case{"long contact", false, 41.7}}) {
    bar::BarSetup setup = test_support::paper_setup();
    if (c.clearance)
      setup.right = {bar::EndType::clearance, 0.5 * test_support::kGap, 0.5 * test_support::kGap};
    contact_bar::OrbitOptions o;
    o.elements = 10;
    const int n = o.elements;
    const contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
    core::Vector x = core::Vector::Zero(n + 1);
    for (int i = 0; i < n; ++i)
      x[i] = 2 * test_support::kGap * std::sin(M_PI * (i + 1) / n) +
             0.1 * test_support::kGap * std::sin(0.7 * (i + 1));
    if (!c.clearance) x[n - 1] = -test_support::kGap;
    x[orbit.period_index()] = c.period;

    // The plain march of the same state: the branch is reached.
    const std::vector<double> nodes = contact_bar::full_state_nodes(orbit, x, 0);
    const core::Vector s = contact_bar::full_state(orbit, x, nodes);
    std::vector<double> u(nodes.size(), 0.0);
    for (int i = 1; i <= n; ++i) u[static_cast<std::size_t>(i)] = s[i - 1];
    bar::BarSetup b = setup;
    b.u0 = bar::PiecewiseLinear(nodes, u);
    b.v0 = bar::PiecewiseLinear(nodes, std::vector<double>(nodes.size(), 0.0));
    contact_bar::TdbemMarch march(
        b, contact_bar::full_state_time_step(orbit, c.period, nodes, 1.0 / 32),
        contact_bar::ContactMethod::event);
    ASSERT_TRUE(march.advance_to(c.period)) << c.name;
    if (c.clearance) {
      const auto& events = march.events();
      const auto closes = [&](bool back) {
        return std::count_if(events.begin(), events.end(), [&](const contact_bar::ContactEvent& e) {
          return e.closing && e.back_wall == back;
        });
      };
      EXPECT_GE(closes(false), 1) << "the front wall is never reached";
      EXPECT_GE(closes(true), 1) << "the back wall is never reached";
    } else {
      EXPECT_GE(march.regauges(), 1) << "the gauge never moves";
    }

    contact_bar::MonodromyOptions by_tangent, by_differences;
    by_tangent.derivatives = contact_bar::MonodromyOptions::Derivatives::tangent;
    by_differences.derivatives = contact_bar::MonodromyOptions::Derivatives::differences;
    core::Matrix M, D;
    ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, by_tangent, M), core::EvalStatus::ok);
    ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, by_differences, D), core::EvalStatus::ok);
    EXPECT_LE((M - D).lpNorm<Eigen::Infinity>(), 1e-7 * M.lpNorm<Eigen::Infinity>()) << c.name;
  }
}

// A clearance end's state on either wall, by the march's tangent (the grid monodromy's default
// there). The map has a kink in u(L): a step towards the wall leaves the admissible set (the march
// refuses it). Oracle: the one-sided difference away from the wall at a tenth of the
// monodromy's step, for the u(L) and v(L) columns (the map is affine on that side, so the two
// agree to the differences' round-off: 1e-16 of the state over 1e-7 of it, times the growth of
// the column; measured 9.7e-10 to 2.0e-8 of the column, 1e-7 asserted).
TEST(ContactBarMonodromy, OnEitherWallOfAClearanceTheTangentIsTheSideAwayFromIt) {
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  bar::BarSetup setup = test_support::paper_setup();
  const double gap = 0.5 * test_support::kGap;
  setup.right = {bar::EndType::clearance, gap, gap};
  contact_bar::OrbitOptions o;
  o.elements = 10;
  const int n = o.elements;
  const contact_bar::ContactBarOrbitProblem orbit(setup, tdbem, o);
  for (double side : {1.0, -1.0}) {  // the front wall (u(L) = gap), the back one (-gap_back)
    core::Vector x = core::Vector::Zero(n + 1);
    for (int i = 0; i < n; ++i)
      x[i] = side * gap * (i + 1) / n + 0.3 * gap * std::sin(0.7 * (i + 1));
    x[n - 1] = side * gap;
    x[orbit.period_index()] = 2.9;
    core::Matrix M;
    ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, {}, M), core::EvalStatus::ok);
    const std::vector<double> nodes = contact_bar::full_state_nodes(orbit, x, 0);
    const core::Vector s = contact_bar::full_state(orbit, x, nodes);
    const double dt = contact_bar::full_state_time_step(orbit, 2.9, nodes, 1.0 / 32);
    for (int j : {n - 1, 2 * n - 1}) {  // u(L), v(L)
      // a tenth of the monodromy's step (1e-6 of max |u0| = gap, times c / L for v)
      const double h = 1e-7 * gap;
      const auto map = [&](double d, core::Vector& f) {
        core::Vector moved = s;
        moved[j] += d;
        return contact_bar::full_state_map(orbit, nodes, 2.9, dt, moved, f);
      };
      core::Vector f0, f_away, f_towards;
      ASSERT_EQ(map(0, f0), core::EvalStatus::ok);
      ASSERT_EQ(map(-side * h, f_away), core::EvalStatus::ok);
      const core::Vector away = side * (f0 - f_away) / h;  // d map / d s_j on the free side
      const double scale = away.lpNorm<Eigen::Infinity>();
      if (j == n - 1) {
        EXPECT_NE(map(side * h, f_towards), core::EvalStatus::ok) << side << ": not on the wall";
      }
      EXPECT_LE((M.col(j) - away).lpNorm<Eigen::Infinity>(), 1e-7 * scale)
          << "side " << side << " column " << j;
    }
  }
}

}  // namespace
