// The mode-1 branch-cost benchmark's pieces (problems/contact_bar/bench/branch_scaling.hpp): the
// exponent fit against an exact power law, the grid list, and the table of two tiny in-process
// traces checked against the closed form.
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.hpp"
#include "problems/contact_bar/bench/branch_scaling.hpp"

using namespace backbone;
using contact_bar::Mode1BranchCost;

namespace {

Mode1BranchCost cost_of(int elements, int points, double cpu_seconds) {
  Mode1BranchCost c;
  c.settings.elements = elements;
  c.points = points;
  c.cpu_seconds = cpu_seconds;
  return c;
}

}  // namespace

// ms per point = 0.02 N^1.7 exactly on N >= 40 (the point counts differ, the time per point does
// not), and an N = 20 run far off the law that the fit must leave out: the least-squares slope of
// exact logs is 1.7 up to the round-off of a few logs, ~1e-14.
TEST(ContactBarBranchScaling, ExponentOfAnExactPowerLawOverTheFittedGrids) {
  std::vector<Mode1BranchCost> runs{cost_of(20, 100, 50.0)};
  for (int n : {40, 80, 160, 320}) {
    const int points = 100 + n;
    runs.push_back(cost_of(n, points, 1e-3 * 0.02 * std::pow(n, 1.7) * points));
  }
  EXPECT_NEAR(contact_bar::time_per_point_exponent(runs, 40), 1.7, 1e-12);
  EXPECT_NEAR(runs[1].ms_per_point(), 0.02 * std::pow(40, 1.7), 1e-12);
  EXPECT_THROW(contact_bar::time_per_point_exponent(runs, 300), core::InputError);  // one run
}

TEST(ContactBarBranchScaling, GridListsAreIncreasingIntervalCounts) {
  EXPECT_EQ(contact_bar::parse_element_list("20, 40 80,160"), (std::vector<int>{20, 40, 80, 160}));
  for (const char* bad : {"", " , ", "40,20", "20,20", "1", "20,x", "2.5", "20;40"})
    EXPECT_THROW(contact_bar::parse_element_list(bad), core::InputError) << "'" << bad << "'";
}

// Two tiny branches (N = 10, 20, up to E = 1.5e-6 J, about twice the start's 7.8e-7): the
// orbits are piecewise linear and held exactly by the TD-BEM with event contact on both grids,
// so the frequency is the closed form's up to the Newton tolerance 3e-9 g0, which moves T by
// less than 1e-9 relative here (the bound of test_peers.cpp).
TEST(ContactBarBranchScaling, TinyBranchesGiveTheTableColumnsAndTheClosedForm) {
  std::vector<Mode1BranchCost> runs;
  for (int n : {10, 20}) {
    contact_bar::Mode1BranchSettings s;
    s.elements = n;
    s.energy_max = 1.5e-6;
    runs.push_back(contact_bar::trace_mode1_cost(s));
    const Mode1BranchCost& c = runs.back();
    ASSERT_TRUE(c.complete) << c.message;
    EXPECT_EQ(c.stop_reason, "bound_reached");
    EXPECT_GE(c.points, 2);
    EXPECT_EQ(c.unknowns.size(), static_cast<std::size_t>(c.points));
    EXPECT_LE(c.worst_error, 1e-9);
    EXPECT_GE(c.jacobians_per_point(), 1.0);  // every point is corrected with a Jacobian
    // The last point is landed on the bound (continuation/README.md, 'Bounds and landing'),
    // solved to the Newton tolerance: far closer than 1e-6 relative.
    EXPECT_NEAR(c.energy_reached / 1.5e-6, 1, 1e-6);
    EXPECT_GT(c.cpu_seconds, 0.0);
  }
  EXPECT_TRUE(contact_bar::same_branch(runs[0], runs[0]));
  EXPECT_FALSE(contact_bar::same_branch(runs[0], runs[1]));  // other grid, other unknowns

  const core::Table t = contact_bar::branch_cost_table(runs);
  EXPECT_EQ(t.columns(), (std::vector<std::string>{"study",
                                                   "setting",
                                                   "start_offset",
                                                   "N",
                                                   "steps_per_period",
                                                   "formulation",
                                                   "newton",
                                                   "test_elements",
                                                   "threads",
                                                   "points",
                                                   "jacobians_per_point",
                                                   "ms_per_point",
                                                   "total_seconds",
                                                   "wall_seconds",
                                                   "worst_closed_form_error",
                                                   "median_closed_form_error",
                                                   "energy_reached",
                                                   "complete",
                                                   "jacobian",
                                                   "sigma_zero_max"}));
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.text_column("setting"), (std::vector<std::string>{"N = 10", "N = 20"}));
  EXPECT_EQ(t.column("N"), (std::vector<double>{10, 20}));
  EXPECT_EQ(t.column("start_offset"),
            (std::vector<double>{runs[0].settings.start_offset, runs[1].settings.start_offset}));
  EXPECT_EQ(t.column("points")[1], runs[1].points);
  EXPECT_DOUBLE_EQ(t.column("ms_per_point")[1], 1e3 * runs[1].cpu_seconds / runs[1].points);
  EXPECT_EQ(t.column("complete"), (std::vector<double>{1, 1}));
}

// Every column of the finite-difference Jacobian is computed by the same operations whatever
// the thread count (core/jacobians/finite_difference.hpp), so 2 threads must give one thread's
// matrix bit for bit; a small grid keeps it fast.
TEST(ContactBarBranchScaling, TwoThreadJacobianIsBitIdentical) {
  const contact_bar::JacobianThreadsTiming t = contact_bar::time_jacobian_threads(10, 1);
  EXPECT_TRUE(t.identical);
  EXPECT_EQ(t.columns, 11);  // 10 nodal values and the period
  EXPECT_EQ(t.rows, 20);     // test_elements auto: 2x the 10 state unknowns
  EXPECT_GT(t.one_thread_seconds, 0.0);
  EXPECT_GT(t.two_thread_seconds, 0.0);
}
