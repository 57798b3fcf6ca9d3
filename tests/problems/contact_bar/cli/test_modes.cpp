// `backbone trace ... --branch modeJ` for J >= 3 (problems/contact_bar/orbits/README.md, section
// 'Mode J'): from grazing to the energy bound, dimension 1 at every point, each point against
// the closed form at its own energy and against the exact oracle (closed_form_check.csv).
#include <gtest/gtest.h>

#include <string>

#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

using backbone::core::Table;

// Tolerances: the frequency is the closed form's to the Newton tolerance (1e-10 relative to the
// amplitude; measured at most 2.5e-13), 1e-10 leaves a margin; the exact-oracle return is the
// trace's own return_tolerance 1e-6 (measured at most 1.7e-9).
TEST(ModesCli, ModesThreeAndEightReachTheEnergyBoundAlongTheirClosedForms) {
  const std::string scene =
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
  for (int mode : {3, 8}) {
    const auto out = cli::scratch("modes", "mode" + std::to_string(mode));
    const cli::Run r = cli::run("trace", scene + " --branch mode" + std::to_string(mode), out);
    ASSERT_EQ(r.code, 0) << r.err;
    const Table b = Table::read_csv(out / "branch.csv");
    const Table c = Table::read_csv(out / "closed_form_check.csv");
    const auto energy = b.column("energy"), dimension = b.column("dimension");
    ASSERT_GE(energy.size(), 10u);
    EXPECT_NEAR(energy.back(), 1e-2, 1e-12) << "the default energy_max";
    const auto error = c.column("relative_error"), ru = c.column("return_error_u"),
               rv = c.column("return_error_v");
    for (std::size_t i = 0; i < energy.size(); ++i) {
      EXPECT_EQ(dimension[i], 1) << "mode " << mode << " point " << i;
      EXPECT_LT(error[i], 1e-10) << "mode " << mode << " point " << i;
      EXPECT_LT(std::max(ru[i], rv[i]), 1e-6) << "mode " << mode << " point " << i;
    }
  }
}

TEST(ModesCli, AModeNeedsTwoIntervalsPerKinkAndNamesLikeModeJ) {
  const std::string scene =
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
  const auto out = cli::scratch("modes", "refused");
  cli::Run r = cli::run("trace", scene + " --branch mode11", out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("shooting_elements"), std::string::npos) << r.err;
  for (const char* bad : {"mode0", "mode03", "modex", "mode-1"}) {
    r = cli::run("trace", scene + " --branch " + bad, out);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.err.find("modeJ for every J >= 1"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(out / "branch.csv"));
}

}  // namespace
