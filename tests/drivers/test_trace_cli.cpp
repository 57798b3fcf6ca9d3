// `backbone trace` end to end on the contact bar: bad input names its key (exit 2, nothing
// written); another scene than the paper's (other L, E, rho, g0 on the command line, nothing
// else changed) traces mode 1 onto the closed form of problems/contact_bar/README.md, 'Mode 1',
// because the continuation works in units of the scene (u0 / g0, T c / L) and checks each point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

namespace fs = std::filesystem;

const std::string paper =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";

void expect_bad_input(const std::string& arguments, const std::string& key) {
  cli::expect_bad_input("trace", arguments, key, "trace_cli");
}

// Traces mode 1 of the paper scene with extra arguments into a scratch folder named `name`;
// every point must match the closed form at its own energy: acceptance 1e-5, asserted 1e-8
// (measured 1e-13, the Newton tolerance 1e-10 g0 propagated). Returns closed_form_check.csv.
backbone::core::Table trace_mode1_on_the_closed_form(const std::string& name,
                                                     const std::string& arguments, fs::path& out) {
  out = cli::scratch("trace_cli", name);
  const cli::Run r = cli::run("trace", paper + " --branch mode1 " + arguments, out);
  EXPECT_EQ(r.code, 0) << r.err;
  if (r.code != 0) return backbone::core::Table({"energy", "relative_error"});
  auto check = backbone::core::Table::read_csv(out / "closed_form_check.csv");
  const auto errors = check.column("relative_error");
  EXPECT_GE(errors.size(), 10u);
  if (!errors.empty()) {
    EXPECT_LE(*std::max_element(errors.begin(), errors.end()), 1e-8);
  }
  return check;
}

TEST(TraceCli, BadInputExitsTwoAndWritesNothing) {
  expect_bad_input(paper + " --branch mode3", "branch");
  expect_bad_input(paper + " --ds 0", "ds");
  expect_bad_input(paper + " --test_elements 5", "test_elements");
  expect_bad_input(paper + " --steps_per_period 41", "steps_per_period");
  expect_bad_input(paper + " --return_tolerance -1", "return_tolerance");
  expect_bad_input(paper + " --right_end free", "right_end");
  // KINSOL is square-only; the default residual is oversampled (test_elements = -1).
  expect_bad_input(paper + " --newton kinsol", "newton");
}

// A short stiff aluminium bar with a 10 um gap: u0 ~ 1e-5 m, T ~ 2e-4 s. The scene's u0 knots
// (written for L = 1) are not needed; the default dimensionless steps fit. Every point must
// match the closed form at its own energy and return under the exact oracle (the per-point
// check of trace, 1e-6).
TEST(TraceCli, OtherSceneModeOneMatchesTheClosedForm) {
  fs::path out;
  const auto check = trace_mode1_on_the_closed_form(
      "short_bar", "--length 0.3 --youngs_modulus 7e4 --density 2.7 --gap 1e-5 --energy_max 1e-3",
      out);
  const auto energy = check.column("energy");
  ASSERT_FALSE(energy.empty());
  EXPECT_NEAR(energy.back(), 1e-3, 1e-9);  // landed on the bound
  // Grazing energy EA g0^2 / (2L) = 7e4 * 1e-10 / 0.6; the start is 5 % above in amplitude.
  EXPECT_NEAR(energy.front(), 1.05 * 1.05 * 7e4 * 1e-10 / 0.6, 1e-15);
  fs::remove_all(out);
}

// Natural continuation in the period, the paper's parameter, on the oversampled residual (the
// bordered predictor once overran its right-hand side there and aborted): T falls from 3.95
// towards 3 L/c, each point on the closed form (measured 2e-13).
TEST(TraceCli, NaturalInThePeriodFollowsModeOne) {
  fs::path out;
  trace_mode1_on_the_closed_form("natural",
                                 "--method natural_then_arclength --natural_direction -1 --ds 0.05 "
                                 "--ds_max 0.05 --energy_max 1e-4",
                                 out);
  const auto period = backbone::core::Table::read_csv(out / "branch.csv").column("period");
  for (std::size_t i = 1; i < period.size(); ++i) EXPECT_LT(period[i], period[i - 1]) << i;
  fs::remove_all(out);
}

// Every scene shipped under problems/*/scenes names a problem the CLI has registered: a problem
// folder with scenes but no register_plugin would fail here (the build registers every folder
// that defines one, drivers/CMakeLists.txt). `trace SCENE --help` resolves the scene's problem
// first and exits 2 naming `problem` when it is unknown.
TEST(TraceCli, EveryShippedSceneNamesARegisteredProblem) {
  int scenes = 0;
  for (const auto& dir : fs::directory_iterator(fs::path(BACKBONE_SOURCE_DIR) / "problems")) {
    if (!fs::is_directory(dir.path() / "scenes")) continue;
    for (const auto& scene : fs::directory_iterator(dir.path() / "scenes")) {
      if (scene.path().extension() != ".ini") continue;
      ++scenes;
      const cli::Run r =
          cli::run("trace", scene.path().string() + " --help", cli::scratch("trace_cli", "help"));
      EXPECT_EQ(r.code, 0) << scene.path() << "\n" << r.err;
    }
  }
  EXPECT_GE(scenes, 3);  // paper, bouncing_bar, duffing at least
}

// An interrupted trace keeps its points and --resume continues it: a 30-point run whose last
// unknowns.csv row is cut (what SIGKILL mid-write leaves) is repaired to 29 complete points and
// resumed to 80; every point matches an uninterrupted 80-point run. Points are converged to
// newton_tolerance = 1e-10 g0, so a restart that re-derives the step direction moves them along
// the curve by that much: 1e-9 relative in period and energy (measured 1.7e-11).
TEST(TraceCli, ResumeContinuesAnInterruptedBranch) {
  const fs::path full = cli::scratch("trace_cli", "full"), part = cli::scratch("trace_cli", "part");
  ASSERT_EQ(cli::run("trace", paper + " --branch mode1 --max_points 80", full).code, 0);
  ASSERT_EQ(cli::run("trace", paper + " --branch mode1 --max_points 30", part).code, 0);
  const fs::path unknowns = part / "unknowns.csv";
  fs::resize_file(unknowns, fs::file_size(unknowns) - 10);  // cut the last row
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             part.string() + "' --max_points 80 > /dev/null 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0);
  const auto a = backbone::core::Table::read_csv(full / "branch.csv");
  const auto b = backbone::core::Table::read_csv(part / "branch.csv");
  ASSERT_EQ(a.rows(), b.rows());
  for (const char* column : {"period", "energy"}) {
    const auto x = a.column(column), y = b.column(column);
    for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(y[i] / x[i], 1.0, 1e-9) << column << i;
  }
  EXPECT_EQ(backbone::core::Table::read_csv(part / "unknowns.csv").rows(),
            backbone::core::Table::read_csv(full / "unknowns.csv").rows());
  fs::remove_all(full);
  fs::remove_all(part);
}

}  // namespace
