// dimension_evidence (continuation/dimension_evidence.hpp), the report of `backbone inspect`, on
// solution sets of known dimension: the unit 2-sphere (2) and the mode-2 orbit of the contact
// bar (1), and its text names the threshold, the gap and every probe.
#include <gtest/gtest.h>

#include "continuation/dimension_evidence.hpp"
#include "problems/algebraic/algebraic.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "tests/continuation/test_support.hpp"

namespace backbone::contact_bar {
using continuation::dimension_evidence;
using continuation::DimensionEvidence;
using continuation::NullProbe;
namespace {

TEST(DimensionEvidence, SphereIsTwoDimensional) {
  const algebraic::Sphere sphere;
  const core::Vector x = core::Vector::Unit(3, 2);  // the north pole
  const DimensionEvidence e =
      dimension_evidence(sphere, x, core::RankOptions{}, core::VerifyOptions{});
  EXPECT_EQ(e.report.verified_dimension, 2);
  ASSERT_EQ(e.probes.size(), 2u);
  for (const NullProbe& p : e.probes) {
    EXPECT_TRUE(p.real);
    // The sphere curves away from its tangent plane by step^2 / 2: drift ~ step / 2 = 5e-4.
    EXPECT_LT(p.drift, 1e-3);
  }
  const std::string text = e.text();
  for (const char* word : {"dimension 2", "threshold", "gap", "direction 2", "neighbour found"})
    EXPECT_NE(text.find(word), std::string::npos) << word << "\n" << text;
}

// The half plane {z = 0, side x >= 0} of R^3 (tests/continuation/test_support.hpp) with J on its
// edge from the solutions' side: at the origin the candidates are the x and y axes in the SVD's
// basis, and a direction whose x component points out of the half plane finds its neighbour
// only on its -d side. The report shows each probe on the side the verification found (every
// "neighbour found" a re-corrected probe within the drift ratio), whichever sign the SVD gives:
// both half planes are checked, so one of them has a direction pointing out.
TEST(DimensionEvidence, OnTheEdgeOfAHalfPlaneEachProbeIsShownOnItsSide) {
  int minus_sides = 0;
  for (const double side : {1.0, -1.0}) {
    const backbone::continuation_tests::HalfPlane half_plane(side, false);
    const DimensionEvidence e = dimension_evidence(half_plane, core::Vector::Zero(3),
                                                   core::RankOptions{}, core::VerifyOptions{});
    EXPECT_EQ(e.report.verified_dimension, 2) << e.text();
    ASSERT_EQ(e.probes.size(), 2u);
    for (const NullProbe& p : e.probes) {
      EXPECT_TRUE(p.real) << e.text();
      EXPECT_TRUE(p.converged && p.drift <= e.drift_ratio) << e.text();
      minus_sides += p.side < 0 ? 1 : 0;
    }
  }
  EXPECT_GE(minus_sides, 1) << "no direction pointed out of its half plane: the case tests nothing";
}

// Mode 2 with its free knot: one dimension (the family), with a gap of many decades.
TEST(DimensionEvidence, ModeTwoIsOneDimensional) {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 1e-3};
  const TdbemSolver tdbem(ContactMethod::event);
  OrbitOptions o;
  o.elements = 20;
  o.steps_per_period = 40;
  o.free_knots = 1;
  o.test_elements = 42;
  const ContactBarOrbitProblem p(s, tdbem, o);
  core::RankOptions rank;
  rank.relative_threshold = 1e-5;  // the trace default of the contact bar
  const DimensionEvidence e =
      dimension_evidence(p, p.contact_family_guess(2, 3.0), rank, core::VerifyOptions{});
  EXPECT_EQ(e.report.verified_dimension, 1) << e.text();
  EXPECT_GT(e.report.gap, 1e4) << e.text();  // a clear gap: one null direction
}

// Mode 1 over two periods (T = 2 T1, near omega1 / 2), started at rest away from the wall: the
// same orbit run twice. Unlike mode 2 over two periods (a 2D continuum, README 'Subharmonic
// continuum'), it is one-dimensional: a member of a continuum would need a second contact phase
// of another shape, and mode 1's two phases per 2 T1 are copies. Amplitudes off the whole
// multiples of g0 (T = 3 + 1/k: contact events on the time grid, where forward differences
// give spurious candidates; README 'Dimension changes').
TEST(DimensionEvidence, ModeOneOverTwoPeriodsIsACurve) {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 1e-3};
  const TdbemSolver tdbem(ContactMethod::event);
  core::RankOptions rank;
  rank.relative_threshold = 1e-5;  // the trace default of the contact bar
  for (const int elements : {20, 40}) {
    OrbitOptions o;
    o.elements = elements;
    o.steps_per_period = 80;  // the dt of 40 steps over one period
    o.test_elements = 2 * elements + 2;
    const ContactBarOrbitProblem p(s, tdbem, o);
    for (const double ratio : {3.3, 7.3}) {
      core::Vector x = p.contact_family_guess(1, ratio);
      x[p.period_index()] *= 2;
      core::Vector r;
      ASSERT_EQ(p.residual(x, r), core::EvalStatus::ok);
      EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-12) << "the closed form solves F over 2 T1";
      const DimensionEvidence e = dimension_evidence(p, x, rank, core::VerifyOptions{});
      EXPECT_EQ(e.report.verified_dimension, 1) << elements << " " << ratio << "\n" << e.text();
      EXPECT_GT(e.report.gap, 1e4) << e.text();  // one clear null direction
    }
  }
}

}  // namespace
}  // namespace backbone::contact_bar
