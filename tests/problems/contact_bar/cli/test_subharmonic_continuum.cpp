// `backbone trace ... --branch subharmonic_continuum` with the branch's own defaults
// (problems/contact_bar/orbits/README.md, section 'Subharmonic continuum'): from the grazing limit
// shape 1 to the bound near shape 0, exit code 0, members checked against the closed forms of
// family.hpp (period 2 T2, energy) and the exact oracle (subharmonic_check.csv).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

using backbone::core::Table;

// The branch starts at a nonsmooth grazing limit, where a finite-difference tangent points off
// the family, and must still pass the turn check with the grid-independent step norm.
// Tolerances: energy and period are fixed by the energy row and the closed form to round-off,
// 1e-8 is the acceptance; the exact return is round-off for exactly represented members, 1e-6
// is the branch's own return_tolerance. shape_end: the bound 1e-6 / D the branch lands on.
// limit_flag: the grazing limit's dimension_flag (below).
void traces_from_limit_to_limit(const std::string& branch, const std::string& energy_key,
                                double shape_end, int limit_flag) {
  const double energy = std::stod(energy_key);
  const std::string scene =
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
  const auto out = cli::scratch(branch, "e" + energy_key);
  const cli::Run r =
      cli::run("trace", scene + " --branch " + branch + " --energy " + energy_key, out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table b = Table::read_csv(out / "branch.csv");
  const Table c = Table::read_csv(out / "subharmonic_check.csv");
  const auto energies = b.column("energy"), period = b.column("period");
  const auto phases = b.column("contact_phases"), grazing = b.column("grazing_instants");
  const auto shape = c.column("shape"), closed = c.column("period_closed_form");
  const auto returns = c.column("return_error"), dimension = b.column("dimension");
  ASSERT_GE(energies.size(), 20u) << "about 40 members by default";
  EXPECT_NEAR(shape.front(), 1, 1e-12);
  EXPECT_LT(shape.back(), 2 * shape_end) << "ends at the bound shape_end";
  EXPECT_EQ(phases.front(), 1);
  EXPECT_EQ(grazing.front(), 1);
  int two_dimensional = 0;
  for (std::size_t i = 0; i < energies.size(); ++i) {
    EXPECT_NEAR(energies[i] / energy, 1, 1e-8) << i;
    EXPECT_NEAR(period[i] / closed[i], 1, 1e-8) << i;
    EXPECT_LT(returns[i], 1e-6) << i;
    if (i > 0) {
      EXPECT_EQ(phases[i], 2) << i;
      EXPECT_EQ(grazing[i], 0) << i;
    }
    two_dimensional += dimension[i] == 2 ? 1 : 0;
  }
  // Every member lies on the 2D manifold (README 'Subharmonic continuum'). The grazing limit
  // (member 0) has F not differentiable there, and the exact Jacobian is one-sided, the side the
  // march resolved: at mode 4's limit the continuum's side, which shows both directions (flag 0);
  // at mode 2's the other, and the 2 comes from J a probe step into the continuum
  // (core::rank_report_beside), flagged 1 (re-checked).
  EXPECT_EQ(two_dimensional, static_cast<int>(energies.size()));
  EXPECT_EQ(b.column("dimension_flag").front(), limit_flag);
  const Table limits = Table::read_csv(out / "limits.csv");
  ASSERT_EQ(limits.rows(), 2u);
  for (double shift : limits.column("shift_distance")) EXPECT_LT(shift, 1e-5);
  for (double p : limits.column("contact_phases")) EXPECT_EQ(p, 1);
}

// Mode 2 at strain 5 g0: b = 0.3, D = 1 - 3b = 0.1, shape_end 1e-5.
TEST(SubharmonicContinuumCli, TracesFromGrazingLimitToGrazingLimitWithItsDefaults) {
  traces_from_limit_to_limit("subharmonic_continuum", "1.25e-5", 1e-5, 1);
}

// Mode 4 at strain 9 g0 (E = 4.05e-5 J): gamma = 1/9, D = (1 - 7 gamma) / 16 = 1/72, shape_end
// 7.2e-5. Its shape-0 limit lives in the chart of 3 knots, shape 1 in that of 4.
TEST(SubharmonicContinuumCli, ModeFourTracesFromGrazingLimitToGrazingLimit) {
  traces_from_limit_to_limit("subharmonic_continuum4", "4.05e-5", 7.2e-5, 0);
}

// Odd modes have none over two periods: refused before any work, naming the branch.
TEST(SubharmonicContinuumCli, OddModesAreRefusedWithTheReason) {
  const std::string scene =
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
  const auto out = cli::scratch("subharmonic3", "refused");
  const cli::Run r = cli::run("trace", scene + " --branch subharmonic3", out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("branch: subharmonic3: mode 3 has no subharmonic continuum"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(out / "branch.csv"));
}

}  // namespace
