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
    // The trivial pair (a Jordan block at +1) moves by the square root of M's error: measured
    // 1.3e-4 to 2.3e-4 here; 1e-3 allows M an error of 1e-6.
    EXPECT_LE(f.trivial_distance, 1e-3) << "N = " << n;
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

// The march's tangent (solver/tdbem.hpp, 'Tangent') against one-sided differences of the same
// march at the same time step: the free bar, modes 1 and 2 (exact on the grid) and mode 1 with a
// perturbed shape. The period map is piecewise affine; mode 1's end turns at T, so u(L, T) is
// V-shaped in the phase (one-sided slopes +-2/3 at 1.5 g0, a kink of the map). Differences of an
// affine map carry the march's round-off (1e-16 of the state) over the step (1e-6 of it), times the
// v rows' c / dx: 1e-8 of |M| leaves a factor of 10 (measured 1.2e-9 to 7e-9 of |M|). Mode 1's
// closed form is the exception: the v rows next to the contact end, in the columns of nodes 6 and
// 7, differ by up to 4.8e-6 of |M| (both one-sided differences agree there to 2e-10 of |M|): a term
// of the tangent is missing, not yet found, which is why the monodromy's default stays differences.
// Its bound, 6e-6, fails if the gap grows. Where the two sides differ the tangent takes their mean,
// as central differences do.
TEST(ContactBarMonodromy, TheTangentIsTheMarchsDerivative) {
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  struct Case {
    const char* name;
    bool free_end;
    int mode;
    double amplitude, period, wiggle;
    double tolerance;  // of |M|
  };
  for (const Case& c : {Case{"free bar", true, 1, 1.5, 3.3, 0.0, 1e-8},
                        Case{"mode 1", false, 1, 1.5, 0.0, 0.0, 6e-6},
                        Case{"mode 1 shape", false, 1, 2.0, 0.0, 0.05, 1e-8},
                        Case{"mode 2", false, 2, 1.5, 0.0, 0.0, 1e-8}}) {
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
    contact_bar::MonodromyOptions by_tangent;
    by_tangent.derivatives = contact_bar::MonodromyOptions::Derivatives::tangent;
    core::Matrix M;
    ASSERT_EQ(contact_bar::full_state_monodromy(orbit, x, by_tangent, M), core::EvalStatus::ok);
    const std::vector<double> nodes = contact_bar::full_state_nodes(orbit, x, 0);
    const core::Vector s = contact_bar::full_state(orbit, x, nodes);
    const double T = x[orbit.period_index()];
    const double dt = contact_bar::full_state_time_step(orbit, T, nodes, 1.0 / 32);
    core::Vector f0, fp, fm;
    ASSERT_EQ(contact_bar::full_state_map(orbit, nodes, T, dt, s, f0), core::EvalStatus::ok);
    const double scale = M.lpNorm<Eigen::Infinity>();
    for (int j = 0; j < 2 * n; ++j) {
      const double h = 1e-6 * std::abs(x[n - 1]);
      core::Vector plus = s, minus = s;
      plus[j] += h;
      minus[j] -= h;
      ASSERT_EQ(contact_bar::full_state_map(orbit, nodes, T, dt, plus, fp), core::EvalStatus::ok);
      ASSERT_EQ(contact_bar::full_state_map(orbit, nodes, T, dt, minus, fm), core::EvalStatus::ok);
      const core::Vector forward = (fp - f0) / h, backward = (f0 - fm) / h;
      for (int i = 0; i < 2 * n; ++i) {
        const double tolerance = c.tolerance * scale;
        EXPECT_LE(std::abs(M(i, j) - 0.5 * (forward[i] + backward[i])), tolerance)
            << c.name << " (" << i << ", " << j << ") " << forward[i] << " " << backward[i];
      }
    }
  }
}
}  // namespace
