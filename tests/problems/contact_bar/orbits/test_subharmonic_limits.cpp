// The grazing limits of the subharmonic continuum located by NLopt (grazing_limits.hpp) and the
// continuum traced between them (problems/contact_bar/orbits/README.md, section 'Subharmonic
// continuum'), against the closed forms of family.hpp and the exact solver.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/grazing_limits.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"

namespace backbone::contact_bar {
namespace {

bar::BarSetup paper_bar() {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 1e-3};
  return s;
}

// Each limit: one contact phase plus one grazing instant, the closed-form period 2 T2 and the
// energy row's energy, u0 equal to the closed-form member at shape 1 / 0, and the two limits
// one orbit shifted by T2. The TD-BEM residual and the exact solver agree to round-off on
// piecewise-linear data and both charts hold the limits exactly, so what is left is NLopt's
// polish onto the rows (1e-12 g0): 1e-8 relative on the period and the energy.
TEST(SubharmonicLimits, NloptFindsBothGrazingLimits) {
  const bar::BarSetup s = paper_bar();
  for (double energy : {1.25e-5, 1e-3}) {
    GrazingLimitOptions o;
    const GrazingLimits g = grazing_limits(s, TdbemSolver(ContactMethod::event), energy, o);
    ASSERT_EQ(g.limits.size(), 2u);
    const double period = 2 * ContactFamily(s.material, 1e-3, 2).period(energy);
    for (const GrazingLimit& l : g.limits) {
      SCOPED_TRACE(l.name + " at " + std::to_string(energy));
      EXPECT_TRUE(l.ok) << l.message;
      // One phase plus one grazing instant, or the vanishing phase shorter than 1e-6 L/c:
      // NLopt locates the kink at the end of the piecewise-smooth curve to the resolution of
      // its forward-difference gradients (step 1e-7 in units of g0 and L), which can leave a
      // phase longer than the 1e-9 T that contact_structure counts as a grazing instant.
      EXPECT_TRUE((l.structure.contact_phases == 1 && l.structure.grazing_instants == 1) ||
                  (l.structure.contact_phases == 2 && l.phase_duration < 1e-6))
          << l.structure.contact_phases << " phases, " << l.structure.grazing_instants
          << " grazing, vanishing phase " << l.phase_duration;
      EXPECT_NEAR(l.period / period, 1, 1e-8);
      EXPECT_NEAR(l.energy / energy, 1, 1e-8);
      EXPECT_LT(l.return_error, 1e-8);
      const SubharmonicMember exact =
          subharmonic_member(s.material, 1e-3, energy, l.name == "shape_1" ? 1.0 : 0.0);
      double du = 0, u_max = 0;
      for (int i = 0; i <= 1000; ++i) {
        const double x = i / 1000.0;
        du = std::max(du, std::abs(l.u0(x) - exact.u0(x)));
        u_max = std::max(u_max, std::abs(exact.u0(x)));
      }
      EXPECT_LT(du / u_max, 1e-5);  // the same resolution along the curve
    }
    EXPECT_LT(g.shift_distance, 1e-5);  // the limits' resolution, as above
  }
}

}  // namespace
}  // namespace backbone::contact_bar
