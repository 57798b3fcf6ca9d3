// The subharmonic continuum near omega2 / 2 (problems/contact_bar/orbits/README.md, section
// 'Subharmonic continuum'): its closed-form members checked by the exact characteristics
// solver (problems/exact_bar), and the TD-BEM started from their in-contact state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "core/rank/rank_report.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/orbits/subharmonic.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {
namespace {

bar::BarSetup paper_setup(const bar::PiecewiseLinear& u0) {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 1e-3};
  s.u0 = u0;
  return s;
}

// How far the exact solution's state at t is from (u, 0), on 401 points: max |u(x, t) - u(x)|
// and max |v(x, t)|, both relative to max |u|.
struct Distance {
  double u = 0, v = 0;
};
Distance distance_at(const exact_bar::ExactBarSolution& sol, double t,
                     const bar::PiecewiseLinear& u) {
  double du = 0, dv = 0, u_max = 0;
  for (int i = 0; i <= 400; ++i) {
    const double x = i / 400.0;
    u_max = std::max(u_max, std::abs(u(x)));
    du = std::max(du, std::abs(sol.u(x, t) - u(x)));
    dv = std::max(dv, std::abs(sol.v(x, t)));
  }
  return {du / u_max, dv / u_max};
}

// Every member, at three energies and across the whole shape range, returns to its u0 and to
// v0 = 0 after T = 2 T2 under the exact solver: exact to round-off (the solver is exact for
// piecewise-linear data), so 1e-12 relative. Energy is EA L s^2 / 2 for every shape.
TEST(SubharmonicContinuum, ClosedFormMembersArePeriodic) {
  const bar::Material m;
  for (double energy : {4.6e-6, 1.25e-5, 1e-3})
    for (double shape : {0.0, 0.1, 0.25, 0.5, 0.8, 1.0}) {
      const SubharmonicMember member = subharmonic_member(m, 1e-3, energy, shape);
      const bar::BarSetup s = paper_setup(member.u0);
      EXPECT_DOUBLE_EQ(s.u0(1.0), 1e-3) << "starts on the wall";
      const exact_bar::ExactBarSolution sol(s, member.period);
      ASSERT_TRUE(sol.ok());
      const Distance back = distance_at(sol, member.period, s.u0);
      EXPECT_LT(back.u, 1e-12) << energy << " " << shape;
      EXPECT_LT(back.v, 1e-12) << energy << " " << shape;
      EXPECT_NEAR(sol.energy(0.5 * member.period) / energy, 1, 1e-12);
    }
}

// The members of the even modes J = 4 and 6 (README.md, 'Subharmonic continuum of mode J'):
// J kinks, period 2 T_J of family.hpp whatever the shape, and under the exact solver a return to
// u0 and v0 = 0 after T (round-off: 1e-11 relative, the J = 2 bound of 1e-12 times the ~5x more
// reflections a period of mode 6 holds; measured 1.2e-12 at worst), with the contact structure of
// the closed form: two phases of 2 shape D and 2 (1 - shape) D inside, one phase and one grazing
// instant at the limits (event times to 1e-12). Energies from just above the mode's grazing
// energy EA ((2J - 1) g0)^2 / (2L) to 1e-3 J.
TEST(SubharmonicContinuum, MembersOfModesFourAndSixArePeriodic) {
  const bar::Material m;
  for (int mode : {4, 6}) {
    const ContactFamily family(m, 1e-3, mode);
    for (double energy : {1.02 * family.grazing_energy(), 1e-4, 1e-3})
      for (double shape : {0.0, 0.2, 0.5, 0.9, 1.0}) {
        const SubharmonicMember member = subharmonic_member(m, 1e-3, energy, shape, mode);
        ASSERT_EQ(member.kinks.size(), static_cast<std::size_t>(mode));
        EXPECT_NEAR(member.period / (2 * family.period(energy)), 1, 1e-14);
        const bar::BarSetup s = paper_setup(member.u0);
        EXPECT_NEAR(s.u0(1.0), 1e-3, 1e-15) << "starts on the wall";
        const exact_bar::ExactBarSolution sol(s, member.period);
        ASSERT_TRUE(sol.ok());
        const Distance back = distance_at(sol, member.period, s.u0);
        EXPECT_LT(back.u, 1e-11) << mode << " " << energy << " " << shape;
        EXPECT_LT(back.v, 1e-11) << mode << " " << energy << " " << shape;
        const ContactStructure c = contact_structure(s, member.period);
        ASSERT_TRUE(c.ok);
        const bool limit = shape == 0.0 || shape == 1.0;
        EXPECT_EQ(c.contact_phases, limit ? 1 : 2) << mode << " " << shape;
        EXPECT_EQ(c.grazing_instants, limit ? 1 : 0) << mode << " " << shape;
        EXPECT_NEAR(c.first_contact, member.first_contact, 1e-12) << mode << " " << shape;
      }
  }
  // Odd modes have no continuum over two periods, and no member below grazing.
  EXPECT_THROW(subharmonic_member(m, 1e-3, 1e-3, 0.3, 3), core::InputError);
  EXPECT_THROW(subharmonic_member(m, 1e-3, 2e-5, 0.3, 4), core::InputError);
}

// The contact structure (problems/contact_bar/orbits/README.md, 'Subharmonic continuum'): interior
// members have two contact phases per period of the closed-form durations (the first one split
// across t = 0 and t = T); at the limits one phase has shrunk to a grazing instant. Durations are
// exact event times (1e-12).
TEST(SubharmonicContinuum, ContactPhasesAndGrazingLimits) {
  const bar::Material m;
  const double energy = 1.25e-5;  // s = 5 g0: b = 0.3, each mode-2 phase lasts 1 - 3b = 0.1
  for (double shape : {0.0, 0.3, 0.5, 1.0}) {
    const SubharmonicMember member = subharmonic_member(m, 1e-3, energy, shape);
    EXPECT_NEAR(member.first_contact + member.second_contact, 0.2, 1e-12);
    const exact_bar::ExactBarSolution sol(paper_setup(member.u0), member.period);
    double first = 0, second = 0;
    for (const auto& c : sol.contact_intervals()) {
      const double release = std::min(c.t_release, member.period);
      if (c.t_close < 0.25 * member.period || c.t_close > 0.75 * member.period)
        first += release - c.t_close;
      else
        second += release - c.t_close;
    }
    EXPECT_NEAR(first, member.first_contact, 1e-12) << shape;
    EXPECT_NEAR(second, member.second_contact, 1e-12) << shape;
    if (shape == 0.0) {
      // Grazing at t = 0: on the wall, zero force, then leaving it (tensile strain at L).
      EXPECT_NEAR(sol.contact_force(1e-9), 0, 1e-15);
      EXPECT_GT(sol.strain(1.0, 0.0), 0);
    }
    if (shape == 1.0) {
      EXPECT_NEAR(sol.u_end(0.5 * member.period), 1e-3, 1e-15);  // grazes at T / 2
    }
  }
  // Mode 2 taken at the centre of its contact phase is the middle member: its two phases are
  // both 1 - 3b long.
  const SubharmonicMember middle = subharmonic_member(m, 1e-3, energy, 0.5);
  EXPECT_NEAR(middle.first_contact, 0.1, 1e-12);
  EXPECT_NEAR(middle.second_contact, 0.1, 1e-12);
}

// The two grazing limits are one orbit shifted by T2 = T / 2: the shape-1 member, simulated
// exactly to T / 2, is at rest in the shape-0 member's u0 (round-off, 1e-12 relative).
TEST(SubharmonicContinuum, GrazingLimitsAreOneOrbitShiftedByHalfThePeriod) {
  const bar::Material m;
  for (double energy : {8e-6, 1.25e-5, 1e-3}) {
    const SubharmonicMember one = subharmonic_member(m, 1e-3, energy, 1.0);
    const SubharmonicMember zero = subharmonic_member(m, 1e-3, energy, 0.0);
    const exact_bar::ExactBarSolution sol(paper_setup(one.u0), one.period);
    const Distance shifted = distance_at(sol, 0.5 * one.period, zero.u0);
    EXPECT_LT(shifted.u, 1e-12) << energy;
    EXPECT_LT(shifted.v, 1e-12) << energy;
  }
}

// The TD-BEM from a state that starts on the wall with a compressive strain: the contact force
// at t = 0 is the true -EA u0_x(L), and the event march follows the exact solver off the time
// grid (dt = 0.013 does not divide the contact instants): the event method is exact for
// piecewise-linear data, so round-off only (1e-12 relative to g0 and the force).
TEST(TdbemStartsInContact, MatchesExactSolver) {
  const bar::Material m;
  for (double shape : {0.3, 0.5, 1.0}) {
    const SubharmonicMember member = subharmonic_member(m, 1e-3, 1.25e-5, shape);
    const bar::BarSetup s = paper_setup(member.u0);
    const exact_bar::ExactBarSolution exact(s, member.period);
    TdbemMarch march(s, 0.013, ContactMethod::event);
    EXPECT_TRUE(march.in_contact(true));
    EXPECT_NEAR(march.end_force(true), exact.contact_force(0.0), 1e-15) << shape;
    EXPECT_NEAR(march.end_force(true), 5e-3, 1e-15);  // EA s
    double worst_u = 0;
    for (int k = 1; k <= 200; ++k) {
      const double t = member.period * k / 200.0;
      march.advance_to(t);
      worst_u = std::max(worst_u, std::abs(march.end_displacement(true) - exact.u_end(t)));
      for (double x : {0.2, 0.55, 0.9})
        worst_u = std::max(worst_u, std::abs(march.displacement(x) - exact.u(x, t)));
    }
    EXPECT_LT(worst_u / 1e-3, 1e-12) << shape;
  }
}

OrbitOptions on_wall(int elements, int free_knots) {
  OrbitOptions o;
  o.elements = elements;
  o.steps_per_period = 40;
  o.free_knots = free_knots;
  o.start_on_wall = true;
  o.test_elements = 2 * o.state_size();
  return o;
}

// Two free knots and u0(L) = g0 held by the representation: every member is a root of the
// residual to round-off with both solvers (the event TD-BEM is exact for piecewise-linear data;
// 1e-12 in units of g0), and u0 is the closed form at every node.
TEST(SubharmonicRepresentation, TwoKnotsHoldTheMembersExactly) {
  const exact_bar::ExactBarSolver exact;
  const TdbemSolver tdbem(ContactMethod::event);
  for (const bar::BarSolver* solver :
       {static_cast<const bar::BarSolver*>(&exact), static_cast<const bar::BarSolver*>(&tdbem)})
    for (double energy : {4.6e-6, 1.25e-5, 1e-4})
      for (double shape : {0.1, 0.5, 0.8, 1.0}) {
        const ContactBarOrbitProblem p(paper_setup({}), *solver, on_wall(20, 2));
        const core::Vector x = p.subharmonic_guess(energy, shape);
        EXPECT_EQ(x.size(), 19 + 2 + 1);  // u0 at nodes 1..19, two knots, T
        core::Vector r;
        ASSERT_EQ(p.residual(x, r), core::EvalStatus::ok);
        EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-12) << energy << " " << shape;
        EXPECT_DOUBLE_EQ(p.initial_displacement(x)(1.0), 1e-3);
        EXPECT_NEAR(p.energy(x) / energy, 1, 1e-12);
      }
}

// One knot cannot hold a member with two kinks off the grid: the residual stays O(1) in units
// of g0 (above 1e-2), so the count of knots matters (problems/contact_bar/orbits/README.md,
// 'Representability').
TEST(SubharmonicRepresentation, OneKnotIsNotEnough) {
  const TdbemSolver tdbem(ContactMethod::event);
  OrbitOptions o = on_wall(20, 2);
  const ContactBarOrbitProblem two(paper_setup({}), tdbem, o);
  const core::Vector x2 = two.subharmonic_guess(1.25e-5, 0.8);
  o.free_knots = 1;
  o.test_elements = 2 * o.state_size();
  const ContactBarOrbitProblem one(paper_setup({}), tdbem, o);
  core::Vector x1(one.num_unknowns());
  const bar::PiecewiseLinear u0 = two.initial_displacement(x2);
  x1[one.knot_index(0)] = x2[two.knot_index(0)];  // first kink on the knot, second between nodes
  const core::Vector y = one.node_positions(x1);
  for (int i = 0; i < o.nodal_unknowns(); ++i) x1[i] = u0(y[i]);
  x1[one.period_index()] = x2[two.period_index()];
  core::Vector r;
  ASSERT_EQ(one.residual(x1, r), core::EvalStatus::ok);
  EXPECT_GT(r.lpNorm<Eigen::Infinity>(), 1e-2);
}

// Knot settings are checked: at most N - 1 knots, reference nodes strictly increasing.
TEST(SubharmonicRepresentation, KnotSettingsAreChecked) {
  OrbitOptions o = on_wall(10, 10);
  EXPECT_THROW(o.validate(), core::InputError);
  o = on_wall(10, 2);
  o.knot_nodes = {5, 3};
  EXPECT_THROW(o.validate(), core::InputError);
  o.knot_nodes = {3};
  EXPECT_THROW(o.validate(), core::InputError);
  o.knot_nodes = {3, 5};
  EXPECT_NO_THROW(o.validate());
}

// The dimension: at members of the continuum the verified rank report of the (column-scaled)
// residual Jacobian finds two null directions (energy and shape) at N = 20 and 40, with a gap
// of at least 1e4 between the kept and the dropped singular values.
// Shapes 0.1 and 0.8: at some other shapes (0.5 = mode 2 itself, 0.25 at N = 40) forward
// differences see one side of a non-smooth coincidence and report extra candidates
// (problems/contact_bar/orbits/README.md, 'Subharmonic continuum'). The knots' reference nodes are
// the nodes nearest the kinks.
TEST(SubharmonicRepresentation, VerifiedDimensionIsTwo) {
  const TdbemSolver tdbem(ContactMethod::event);
  for (int n : {20, 40})
    for (double shape : {0.1, 0.8}) {
      OrbitOptions o = on_wall(n, 2);
      const SubharmonicMember member = subharmonic_member(bar::Material{}, 1e-3, 1.25e-5, shape);
      o.knot_nodes = nearest_knot_nodes(n, 1.0, {member.kinks[0], member.kinks[1]});
      const ContactBarOrbitProblem p(paper_setup({}), tdbem, o);
      const continuation::ScaledProblem scaled(p);
      const core::Vector z = scaled.to_scaled(p.subharmonic_guess(1.25e-5, shape));
      core::Matrix J;
      ASSERT_EQ(scaled.jacobian(z, J), core::EvalStatus::ok);
      core::RankOptions rank;
      rank.relative_threshold = 1e-5;  // the trace default (plugin.cpp, rank_threshold)
      core::RankReport report = core::rank_report(J, rank);
      const core::VerifyOptions verify;
      auto verifier = core::make_verifier(verify, rank);
      core::verify_null_directions(scaled, z, *verifier, verify, report);
      EXPECT_EQ(report.nullity, 2) << n << " " << shape << " " << report.summary();
      EXPECT_EQ(report.verified_dimension, 2) << n << " " << shape << " " << report.summary();
      EXPECT_GT(report.gap, 1e4) << report.summary();
    }
}

// The contact structure counted from the exact simulation: two phases inside the continuum, one
// phase plus one grazing instant at either limit (problems/contact_bar/orbits/README.md,
// 'Subharmonic continuum'), no penetration (min_gap >= 0 to round-off) and the phase through t = 0
// counted across t = T.
TEST(SubharmonicContinuum, ContactStructureFromTheExactSimulation) {
  const bar::Material m;
  for (double shape : {0.0, 0.2, 0.5, 0.9, 1.0}) {
    const SubharmonicMember member = subharmonic_member(m, 1e-3, 1.25e-5, shape);
    const ContactStructure c = contact_structure(paper_setup(member.u0), member.period);
    ASSERT_TRUE(c.ok);
    const bool limit = shape == 0.0 || shape == 1.0;
    EXPECT_EQ(c.contact_phases, limit ? 1 : 2) << shape;
    EXPECT_EQ(c.grazing_instants, limit ? 1 : 0) << shape;
    // The grazing reaches the wall as a front arrives (u(L, t) is piecewise linear: its
    // maximum is a front's arrival), a kink the exact march resolves to round-off.
    EXPECT_EQ(c.closings_on_fronts, limit ? 1 : 0) << shape;
    EXPECT_GE(c.min_gap, -1e-15) << shape;
    EXPECT_NEAR(c.first_contact, member.first_contact, 1e-12) << shape;
  }
}

// Path rows: the energy row and the shape row vanish at a member of that energy and shape and
// not elsewhere; set_path_rows(false) leaves the periodicity residual F alone.
TEST(SubharmonicRepresentation, PathRowsPickTheMember) {
  const TdbemSolver tdbem(ContactMethod::event);
  OrbitOptions o = on_wall(20, 2);
  o.fixed_energy = 1.25e-5;
  o.fixed_shape = 0.3;
  ContactBarOrbitProblem p(paper_setup({}), tdbem, o);
  EXPECT_EQ(p.num_equations(), o.test_elements + 2);
  core::Vector r;
  ASSERT_EQ(p.residual(p.subharmonic_guess(1.25e-5, 0.3), r), core::EvalStatus::ok);
  EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_NEAR(p.subharmonic_shape(p.subharmonic_guess(1.25e-5, 0.3)), 0.3, 1e-14);
  ASSERT_EQ(p.residual(p.subharmonic_guess(2e-5, 0.3), r), core::EvalStatus::ok);
  EXPECT_NEAR(r[o.test_elements], 0.6, 1e-12);    // (2e-5 - 1.25e-5) / 1.25e-5
  EXPECT_NEAR(r[o.test_elements + 1], 0, 1e-11);  // in units of g0: knots to 1e-14 L
  ASSERT_EQ(p.residual(p.subharmonic_guess(1.25e-5, 0.7), r), core::EvalStatus::ok);
  EXPECT_GT(std::abs(r[o.test_elements + 1]), 1e-3);
  p.set_path_rows(false);
  EXPECT_EQ(p.num_equations(), o.test_elements);
  ASSERT_EQ(p.residual(p.subharmonic_guess(2e-5, 0.7), r), core::EvalStatus::ok);
  EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-12);
}

// F alone keeps the formulation the curve was traced with: the atlas and the rank reports of F
// alone (without_path_rows) solve that residual. Off the continuum (one value moved), the paper
// and the regular residuals differ, so the rows must match the formulation's, bit for bit.
TEST(SubharmonicRepresentation, FAloneKeepsTheFormulation) {
  const TdbemSolver tdbem(ContactMethod::event);
  OrbitOptions o = on_wall(20, 2);
  o.fixed_energy = 1.25e-5;
  ContactBarOrbitProblem p(paper_setup({}), tdbem, o);
  core::Vector x = p.subharmonic_guess(1.25e-5, 0.3);
  x[3] *= 1.1;
  core::Vector previous;
  for (const auto f : {core::ShootingFormulation::displacement_periodicity,
                       core::ShootingFormulation::half_period_velocity}) {
    p.set_formulation(f);
    const ContactBarOrbitProblem alone = p.without_path_rows();
    EXPECT_EQ(alone.formulation(), f);
    EXPECT_EQ(alone.num_equations(), p.num_equations() - 1);
    core::Vector full, r;
    ASSERT_EQ(p.residual(x, full), core::EvalStatus::ok);
    ASSERT_EQ(alone.residual(x, r), core::EvalStatus::ok);
    EXPECT_GT(r.lpNorm<Eigen::Infinity>(), 1e-3);
    EXPECT_EQ(r, full.head(r.size()));
    if (previous.size() == r.size()) {
      EXPECT_GT((r - previous).lpNorm<Eigen::Infinity>(), 1e-3);
    }
    previous = r;
  }
}

}  // namespace
}  // namespace backbone::contact_bar
