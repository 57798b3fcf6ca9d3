// The BarSolver face of the exact solver: snapshots (nodal values, exact hat projections,
// averages on fronts), histories, and bad input reported as InputError naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/errors.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"

namespace backbone::exact_bar {
namespace {

bar::BarSetup mode_one() {
  bar::BarSetup s;
  s.right = {bar::EndType::contact, 1e-3};
  s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, -0.01});
  return s;
}

TEST(ExactBarSnapshot, ProjectionsOfModeOneAtItsPeriodAreThoseOfU0) {
  // u(., T) = eps x exactly, v(., T) = 0. Hand integrals of eps x against the hats of a
  // uniform grid (h = L / n): interior nodes h eps x_i, first node eps h^2 / 6, last node
  // eps (L h / 2 - h^2 / 6).
  const ExactBarSolver solver;
  bar::SnapshotRequest r;
  r.elements = 7;  // nodes that never sit on a round number
  r.nodal_u = r.nodal_v = r.projected_u = r.projected_v = true;
  const bar::FieldSnapshot f = solver.snapshot(mode_one(), 3.1, r);
  ASSERT_TRUE(f.ok);
  ASSERT_EQ(f.x.size(), 8u);
  const double eps = -0.01, h = 1.0 / 7;
  for (std::size_t i = 0; i < f.x.size(); ++i) {
    EXPECT_NEAR(f.u[i], eps * f.x[i], 1e-17);
    EXPECT_NEAR(f.v[i], 0.0, 1e-16);
    EXPECT_NEAR(f.v_projected[i], 0.0, 1e-17);
    double expected = h * eps * f.x[i];
    if (i == 0) expected = eps * h * h / 6;
    if (i == 7) expected = eps * (h / 2 - h * h / 6);
    EXPECT_NEAR(f.u_projected[i], expected, 1e-18) << i;
  }
}

TEST(ExactBarSnapshot, ProjectionsWithFrontsInsideCellsMatchTheHandSolution) {
  // Mode 1 (L = c = 1, eps = -0.01, g0 = 1e-3) at t = 1.3, in contact since 1.1. By hand from
  // the characteristics: R+ = -0.01 for x < 0.3 (released by the fixed end after t = 1),
  // +0.01 beyond; R- = +0.01 for x < 0.8, -0.01 beyond (reflected by the wall since 1.1). So
  //   v = 0 on [0, 0.3), 0.01 on (0.3, 0.8), 0 on (0.8, 1];
  //   u = 0.01 x up to 0.3, 0.003 up to 0.8, then 0.003 - 0.01 (x - 0.8) (u(1) = g0).
  // Projections of these on 7 hats (fronts inside cells), integrated exactly by Simpson on
  // the pieces between fronts and nodes.
  auto u_hand = [](double x) {
    return x < 0.3 ? 0.01 * x : x < 0.8 ? 0.003 : 0.003 - 0.01 * (x - 0.8);
  };
  auto v_hand = [](double x) { return x > 0.3 && x < 0.8 ? 0.01 : 0.0; };
  const int n = 7;
  const double h = 1.0 / n;
  std::vector<double> pu(n + 1, 0.0), pv(n + 1, 0.0);
  for (int j = 0; j < n; ++j) {
    std::vector<double> cuts{j * h, (j + 1) * h};
    for (double f : {0.3, 0.8})
      if (f > j * h && f < (j + 1) * h) cuts.insert(cuts.end() - 1, f);
    for (std::size_t q = 0; q + 1 < cuts.size(); ++q) {
      const double a = cuts[q], b = cuts[q + 1], m = 0.5 * (a + b), w = (b - a) / 6;
      auto hat_left = [&](double x) { return ((j + 1) * h - x) / h; };
      auto hat_right = [&](double x) { return (x - j * h) / h; };
      // v is constant inside (a, b): evaluate it at the midpoint only.
      const double vm = v_hand(m);
      pu[j] +=
          w * (u_hand(a) * hat_left(a) + 4 * u_hand(m) * hat_left(m) + u_hand(b) * hat_left(b));
      pu[j + 1] +=
          w * (u_hand(a) * hat_right(a) + 4 * u_hand(m) * hat_right(m) + u_hand(b) * hat_right(b));
      pv[j] += vm * 0.5 * (hat_left(a) + hat_left(b)) * (b - a);
      pv[j + 1] += vm * 0.5 * (hat_right(a) + hat_right(b)) * (b - a);
    }
  }
  const ExactBarSolution sol = solve(mode_one(), 3.1);
  bar::SnapshotRequest r;
  r.elements = n;
  r.nodal_u = r.nodal_v = r.projected_u = r.projected_v = true;
  const bar::FieldSnapshot f = sol.snapshot(1.3, r);
  ASSERT_TRUE(f.ok);
  for (int i = 0; i <= n; ++i) {
    // Scale 0.01 h (field ~0.01 times the hat's integral): 1e-13 relative to it.
    EXPECT_NEAR(f.u_projected[i], pu[i], 1e-13 * 0.01 * h) << i;
    EXPECT_NEAR(f.v_projected[i], pv[i], 1e-13 * 0.01 * h) << i;
    EXPECT_NEAR(f.u[i], u_hand(f.x[i]), 1e-17) << i;
    EXPECT_NEAR(f.v[i], v_hand(f.x[i]), 1e-17) << i;
  }
  EXPECT_GT(f.v_projected[3], 1e-4);  // the moving band is seen by the projection
}

TEST(ExactBarSnapshot, VelocityOnAFrontIsTheAverageOfBothSides) {
  // Fixed-fixed tent u0 (slope s = 0.02 then -0.02), c = 1: for t < 1/2 the middle band
  // |x - 1/2| < t moves with v = -c s * 2 / 2 ... (d'Alembert: v = c (U'(x+t) - U'(x-t)) / 2
  // = -0.02 inside, 0 outside). At t = 1/4 the fronts sit on nodes 1/4 and 3/4 exactly.
  bar::BarSetup s;
  s.right = {bar::EndType::fixed, 0};
  s.u0 = bar::PiecewiseLinear({0.0, 0.5, 1.0}, {0.0, 0.01, 0.0});
  bar::SnapshotRequest r;
  r.elements = 4;
  r.nodal_v = true;
  const bar::FieldSnapshot f = ExactBarSolver().snapshot(s, 0.25, r);
  EXPECT_NEAR(f.v[0], 0.0, 1e-18);
  EXPECT_NEAR(f.v[1], -0.01, 1e-17);  // front: average of 0 and -0.02
  EXPECT_NEAR(f.v[2], -0.02, 1e-17);
  EXPECT_NEAR(f.v[3], -0.01, 1e-17);
  EXPECT_NEAR(f.v[4], 0.0, 1e-18);
  EXPECT_NEAR(f.u[2], 0.01 - 0.25 * 0.02, 1e-17);
}

TEST(ExactBarSimulate, HistoryColumnsAndSampling) {
  const ExactBarSolver solver;
  EXPECT_EQ(solver.name(), "exact");
  bar::SimulationOptions o;
  o.t_end = 3.1;
  o.dt = 0.01;  // 310 steps: 311 rows
  o.history_samples = 2000;
  o.probes = {0.5};
  const bar::History h = solver.simulate(mode_one(), o);
  ASSERT_EQ(h.t.size(), 311u);
  ASSERT_EQ(h.energy.size(), 311u);
  ASSERT_EQ(h.probe_u.size(), 1u);
  EXPECT_EQ(h.t.back(), 3.1);
  EXPECT_NEAR(h.u_contact.back(), -0.01, 1e-16);
  EXPECT_NEAR(h.probe_u[0].back(), -0.005, 1e-16);
  EXPECT_NEAR(h.contact_force[150], 0.01, 1e-16);  // t = 1.5
  EXPECT_EQ(h.contact_force[100], 0.0);            // t = 1.0: flying
  for (double e : h.energy) EXPECT_NEAR(e, 0.5e-4, 1e-17);
  o.history_samples = 11;
  EXPECT_EQ(solver.simulate(mode_one(), o).t.size(), 11u);
  EXPECT_EQ(solver.simulate(mode_one(), o).t[5], 1.55);
}

template <class F>
void expect_input_error(const std::string& key, F&& f) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << key;
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
  }
}

TEST(ExactBarApi, BadInputNamesTheKey) {
  const ExactBarSolver solver;
  expect_input_error("t_end", [] { solve(mode_one(), -1.0); });
  expect_input_error("t", [] { solve(mode_one(), 1.0).u(0.5, 2.0); });
  expect_input_error("x", [] { solve(mode_one(), 1.0).u(1.5, 0.5); });
  expect_input_error("t", [&] { solver.snapshot(mode_one(), -0.1, {}); });
  bar::SimulationOptions o;
  o.probes = {2.0};
  expect_input_error("probes", [&] { solver.simulate(mode_one(), o); });
  bar::BarSetup bad = mode_one();
  bad.right.gap = -1;
  expect_input_error("gap", [&] { solve(bad, 1.0); });
  bar::SnapshotRequest r;
  r.elements = 0;
  expect_input_error("elements", [&] { solver.snapshot(mode_one(), 1.0, r); });
}

TEST(ExactBarApi, LongRunCostIsPerSegmentNotPerStep) {
  // 1000 periods of mode 1: the solution must stay exact and the stored segments must grow
  // linearly with the number of windows (no accumulation of ulp-long slivers).
  const double T = 3.1;
  const ExactBarSolution sol = solve(mode_one(), 1000 * T);
  EXPECT_LT(sol.segment_count(), 20u * 3100u);
  EXPECT_EQ(sol.contact_intervals().size(), 1000u);
  for (int i = 0; i <= 10; ++i) EXPECT_NEAR(sol.u(0.1 * i, 1000 * T), -0.001 * i, 1e-14);
  EXPECT_NEAR(sol.energy(999.5 * T), 0.5e-4, 1e-16);
}

}  // namespace
}  // namespace backbone::exact_bar
