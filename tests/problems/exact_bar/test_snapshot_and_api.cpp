// The BarSolver face of the exact solver: snapshots (nodal values, exact hat projections,
// averages on fronts), histories, and bad input reported as InputError naming the key.
#include <gtest/gtest.h>

#include <cmath>

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

TEST(ExactBarSnapshot, HalfPeriodVelocityProjectionOfModeOne) {
  // At T/2 = 1.55 the bar is in contact and fronts cross the grid cells: the exact
  // projections must agree with a brute-force quadrature of the solution's own pointwise
  // v and u (this checks the projection code path, not the dynamics).
  const ExactBarSolution sol = solve(mode_one(), 3.1);
  bar::SnapshotRequest r;
  r.elements = 10;
  r.nodal_u = false;
  r.projected_v = true;
  r.projected_u = true;
  const bar::FieldSnapshot f = sol.snapshot(1.55, r);
  const double h = 0.1;
  for (int i = 0; i <= 10; ++i) {
    double pv = 0, pu = 0;
    const int n = 20000;  // midpoint rule on a fine grid: error O(h^2 / n^2) away from fronts
    for (int k = 0; k < n; ++k) {
      const double x = std::max(0.0, (i - 1) * h) +
                       (k + 0.5) / n * (std::min(1.0, (i + 1) * h) - std::max(0.0, (i - 1) * h));
      const double w = (std::min(1.0, (i + 1) * h) - std::max(0.0, (i - 1) * h)) / n;
      const double hat = 1 - std::abs(x - i * h) / h;
      pv += sol.v(x, 1.55) * hat * w;
      pu += sol.u(x, 1.55) * hat * w;
    }
    EXPECT_NEAR(f.v_projected[i], pv, 1e-7 * 0.01 * h) << i;
    EXPECT_NEAR(f.u_projected[i], pu, 1e-9 * 0.01 * h) << i;
  }
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
