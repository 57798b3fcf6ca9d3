// `backbone trace scenes/clearance.ini --branch modeJ` (problems/contact_bar/orbits/README.md,
// section 'Modes in a clearance'): from grazing to the energy bound, dimension 1 at every point,
// each point against ClearanceMode at its own energy, the exact oracle, and the phases on each
// wall counted by an exact simulation (closed_form_check.csv).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

using backbone::core::Table;

cli::Run trace_clearance(const std::string& arguments, const std::filesystem::path& out) {
  return cli::run(
      "trace",
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/clearance.ini " + arguments,
      out);
}

// Tolerances: the frequency is the closed form's to the Newton tolerance (1e-10 of the
// amplitude; measured at most 1e-12), 1e-10 leaves a margin; the return is the trace's own
// return_tolerance 1e-6 (measured at most 5e-9). The asymmetric clearance (back wall 3 gap
// behind) is the one-sided mode up to s L = J g_back + (J - 1) g (mode 2: E = 2.45e-5 J), then
// holds both walls; the branch crosses that corner.
TEST(ClearanceCli, ModesOneAndTwoHoldOneWallThenBoth) {
  for (const char* mode : {"mode1", "mode2"}) {
    const auto out = cli::scratch("clearance", mode);
    const cli::Run r = trace_clearance(
        std::string("--branch ") + mode + " --gap_back 3e-3 --energy_max 1e-3", out);
    ASSERT_EQ(r.code, 0) << r.err;
    const Table b = Table::read_csv(out / "branch.csv");
    const Table c = Table::read_csv(out / "closed_form_check.csv");
    const auto energy = c.column("energy"), dimension = b.column("dimension");
    ASSERT_GE(energy.size(), 10u);
    EXPECT_NEAR(energy.back(), 1e-3, 1e-15);
    const double back_grazing = std::string(mode) == "mode1" ? 4.5e-6 : 2.45e-5;  // EA (s L)^2/2L
    const auto error = c.column("relative_error"), ru = c.column("return_error_u"),
               rv = c.column("return_error_v"), front = c.column("front_phases"),
               back = c.column("back_phases"), one_sided = c.column("one_sided_relative_error");
    int both = 0, one = 0;
    for (std::size_t i = 0; i < energy.size(); ++i) {
      EXPECT_EQ(dimension[i], 1) << mode << " point " << i;
      EXPECT_LT(error[i], 1e-10) << mode << " point " << i;
      EXPECT_LT(std::max(ru[i], rv[i]), 1e-6) << mode << " point " << i;
      EXPECT_EQ(front[i], 1) << mode << " point " << i;
      // Off the corner by more than the Newton tolerance's worth of energy.
      if (std::abs(energy[i] / back_grazing - 1) < 1e-8) continue;
      const bool above = energy[i] > back_grazing;
      EXPECT_EQ(back[i], above ? 1 : 0) << mode << " point " << i << " E " << energy[i];
      if (!above) {
        EXPECT_LT(one_sided[i], 1e-10) << "one-sided mode recovered, point " << i;
      }
      (above ? both : one) += 1;
    }
    EXPECT_GE(one, 3) << "points below the back wall's grazing";
    EXPECT_GE(both, 3) << "points above it";
  }
}

TEST(ClearanceCli, ABadClearanceIsRefusedBeforeAnyWork) {
  const auto out = cli::scratch("clearance", "refused");
  struct Case {
    const char* arguments;
    const char* key;
  } cases[] = {{"--branch mode1 --gap_back 0", "gap_back"},
               {"--branch mode1 --gap_back 5e-4", "gap_back"},
               {"--branch mode1 --right_end contact", "gap_back"},
               {"--branch mode1 --follow all", "follow"},
               {"--branch mode2 --free_knots 1", "free_knots"},
               {"--branch subharmonic", "right_end"}};
  for (const Case& c : cases) {
    const cli::Run r = trace_clearance(c.arguments, out);
    EXPECT_EQ(r.code, 2) << c.arguments;
    EXPECT_NE(r.err.find(c.key), std::string::npos) << c.arguments << ": " << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(out / "branch.csv"));
}

}  // namespace
