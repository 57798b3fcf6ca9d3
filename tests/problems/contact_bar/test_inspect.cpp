// dimension_evidence (problems/contact_bar/inspect.hpp), the report of `backbone inspect`, on
// solution sets of known dimension: the unit 2-sphere (2) and the mode-2 orbit of the contact
// bar (1), and its text names the threshold, the gap and every probe.
#include <gtest/gtest.h>

#include "problems/algebraic/algebraic.hpp"
#include "problems/contact_bar/inspect.hpp"
#include "problems/contact_bar/periodic_bar.hpp"
#include "problems/contact_bar/tdbem.hpp"

namespace backbone::contact_bar {
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
  EXPECT_GT(e.report.gap, 1e4) << e.text();  // measured 2e7 on the traced branch
}

}  // namespace
}  // namespace backbone::contact_bar
