// attached_content (problems/contact_bar/orbits/attached_content.hpp) against linear modes: on a
// bar that never reaches its wall the motion is the fixed-free bar's, so a linear mode k added to
// another orbit of period 4L/c is content of exactly 2k - 1 oscillations per period.
#include <gtest/gtest.h>

#include "problems/contact_bar/orbits/attached_content.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "tests/problems/contact_bar/paper_setup.hpp"

namespace {

using backbone::contact_bar::ContactBarOrbitProblem;
using backbone::contact_bar::OrbitOptions;

TEST(AttachedContent, ALinearModeAddedToTheFundamentalIsItsHarmonic) {
  const backbone::exact_bar::ExactBarSolver exact;
  OrbitOptions o;
  o.elements = 40;
  const ContactBarOrbitProblem problem(test_support::paper_setup(), exact, o);
  // Mode 1 at half the gap (period 4 L/c), plus mode k (harmonic 2k - 1) at a tenth of the
  // gap: the end stays 0.4 g0 off the wall, so no contact and both motions are linear.
  const backbone::core::Vector base = problem.linear_mode_guess(1, 0.5);
  for (int k : {2, 3}) {
    const backbone::core::Vector mode = problem.linear_mode_guess(k, 0.1);
    backbone::core::Vector attached = base;
    for (int i = 0; i < o.nodal_unknowns(); ++i) attached[i] += mode[i];
    ASSERT_DOUBLE_EQ(attached[problem.period_index()], 4.0);
    const auto c = backbone::contact_bar::attached_content(problem, base, attached, exact);
    EXPECT_EQ(c.frequency_ratio, 2 * k - 1) << "mode " << k;
    EXPECT_EQ(c.oscillations_per_period, 2 * k - 1) << "mode " << k;
    // The end's content peaks at its start value 0.1 g0; the mean over the period the measure
    // removes is that of a piecewise-linear sine on 40 elements, O((5 pi / 80)^2) = 4e-2 of
    // it at most.
    EXPECT_NEAR(c.amplitude, 0.1 * test_support::kGap, 4e-2 * 0.1 * test_support::kGap);
  }
}

}  // namespace
