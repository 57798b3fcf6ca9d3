// `backbone trace` on problems that give their orbits' monodromy: the stability files, and bad
// input of a forced hybrid problem refused before any work (exit 2, one line naming the key,
// nothing written).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/io/scene_ini.hpp"
#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

namespace fs = std::filesystem;

const std::string impact =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/impact_oscillator/scenes/impact.ini";
const std::string duffing =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/duffing/scenes/duffing.ini";
const std::string paper =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";

}  // namespace

TEST(StabilityInput, ForcingFrequencyMustBePositive) {
  cli::expect_bad_input("trace", impact + " --frequency 0", "frequency", "stability_cli");
  cli::expect_bad_input("trace", impact + " --frequency -2.8", "frequency", "stability_cli");
}

TEST(StabilityInput, ResonantForcingFrequencyIsRefused) {
  cli::expect_bad_input("trace", impact + " --frequency 3", "frequency", "stability_cli");
}

TEST(StabilityInput, RestitutionOutsideItsRangeIsRefused) {
  cli::expect_bad_input("trace", impact + " --restitution 0", "restitution", "stability_cli");
  cli::expect_bad_input("trace", impact + " --restitution 1.5", "restitution", "stability_cli");
  cli::expect_bad_input("trace", impact + " --restitution nan", "restitution", "stability_cli");
}

// The wall above the orbit's reach: no impact ever happens (the event never fires).
TEST(StabilityInput, WallBeyondTheGrazingHasNoOrbit) {
  cli::expect_bad_input("trace", impact + " --wall 0.5 --wall_max 1", "wall", "stability_cli");
}

TEST(StabilityInput, WindowAroundTheStartIsChecked) {
  cli::expect_bad_input("trace", impact + " --wall_min 0.1", "wall_min", "stability_cli");
  cli::expect_bad_input("trace", impact + " --wall_max -0.1", "wall_max", "stability_cli");
  // The start's impact velocity (0.34) below the grazing bound: the key that sets it is named.
  cli::expect_bad_input("trace", impact + " --grazing_velocity 100", "grazing_velocity",
                        "stability_cli");
  cli::expect_bad_input("trace", impact + " --continuation_parameter mass",
                        "continuation_parameter", "stability_cli");
}

TEST(StabilityInput, FloquetTolerancesAreChecked) {
  cli::expect_bad_input("trace", impact + " --floquet_tolerance 0", "floquet_tolerance",
                        "stability_cli");
  cli::expect_bad_input("trace", duffing + " --floquet_trivial_tolerance 2",
                        "floquet_trivial_tolerance", "stability_cli");
  cli::expect_bad_input("trace", impact + " --follow doubles", "follow", "stability_cli");
  cli::expect_bad_input("trace", paper + " --branch mode1 --stability_growth_periods -1",
                        "stability_growth_periods", "stability_cli");
  cli::expect_bad_input("trace", paper + " --branch mode1 --stability_growth_periods 10001",
                        "stability_growth_periods", "stability_cli");
}

// A branch with multipliers writes them, with the stability columns, and its bifurcations.
TEST(StabilityFiles, ImpactOscillatorBranchWritesItsMultipliersAndBifurcations) {
  const fs::path out = cli::scratch("stability_cli", "impact_up");
  const cli::Run r = cli::run("trace", impact + " --max_points 60", out);
  ASSERT_EQ(r.code, 0) << r.err;
  const backbone::core::Table branch = backbone::core::Table::read_csv(out / "branch.csv");
  const backbone::core::Table multipliers =
      backbone::core::Table::read_csv(out / "multipliers.csv");
  // Two multipliers per point (the state is (x, v)), each point's stable flag decided.
  EXPECT_EQ(multipliers.rows(), 2 * branch.rows());
  const std::vector<double> stable = branch.column("stable");
  for (const double s : stable) EXPECT_TRUE(s == 0 || s == 1);
  // summary.txt counts them: every point once, none undecided; no branch points sought.
  const auto summary = [&](const char* key) {
    return backbone::core::read_text_value(out / "summary.txt", key);
  };
  EXPECT_EQ(summary("stable_points"),
            std::to_string(std::count(stable.begin(), stable.end(), 1.0)));
  EXPECT_EQ(summary("unstable_points"),
            std::to_string(std::count(stable.begin(), stable.end(), 0.0)));
  EXPECT_EQ(summary("undecided_points"), "0");
  EXPECT_EQ(summary("branch_points_located"), "-");
  const backbone::core::Table found = backbone::core::Table::read_csv(out / "bifurcations.csv");
  ASSERT_EQ(found.rows(), 1u);
  EXPECT_EQ(found.text_column("type")[0], "grazing");
  EXPECT_TRUE(fs::exists(out / "branch.png"));
  // The hybrid orbit's Jacobian is its own (HybridOrbitProblem::compute_jacobian), not the
  // default differences, and summary.txt says so.
  EXPECT_TRUE(
      backbone::core::read_text_value(out / "summary.txt", "jacobian").starts_with("variational"));
}

// Stability off: the same branch without the files or columns.
TEST(StabilityFiles, StabilityOffWritesNoMultipliers) {
  const fs::path out = cli::scratch("stability_cli", "duffing_off");
  const cli::Run r = cli::run("trace", duffing + " --stability false --max_points 5", out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "multipliers.csv"));
  EXPECT_EQ(backbone::core::read_text_value(out / "summary.txt", "stable_points"), "-");
  const backbone::core::Table branch = backbone::core::Table::read_csv(out / "branch.csv");
  EXPECT_EQ(std::count(branch.columns().begin(), branch.columns().end(), "stable"), 0);
  // Duffing's shooting Jacobian is OdeOrbitProblem's, from the variational equations.
  EXPECT_EQ(backbone::core::read_text_value(out / "summary.txt", "jacobian"),
            "analytic (the variational equations)");
}

// The bar's mode 2 with K also by the TD-BEM's own march: every point has both, and they agree
// to the differences' round-off (the unit test TheTdbemsKMatchesTheExactSolversTangent bounds
// it by 1e-8 on closed forms; a traced orbit's K carries its residual too: 1e-6).
TEST(StabilityFiles, BarModeTwoWritesTheTdbemsKBesideTheExactOne) {
  const fs::path out = cli::scratch("stability_cli", "bar_mode2_tdbem");
  const cli::Run r = cli::run("trace",
                              paper +
                                  " --branch mode2 --shooting_elements 20 --max_points 8 "
                                  "--stability true --stability_tdbem_check true",
                              out);
  ASSERT_EQ(r.code, 0) << r.err;
  const backbone::core::Table fronts = backbone::core::Table::read_csv(out / "fronts.csv");
  ASSERT_GT(fronts.rows(), 0u);
  for (const double ok : fronts.column("tdbem_ok")) EXPECT_EQ(ok, 1.0);
  for (const double d : fronts.column("tdbem_k_difference")) EXPECT_LT(d, 1e-6);
  for (const double n : fronts.column("fronts")) EXPECT_EQ(n, 3.0);
  for (const double g : fronts.column("grazing_instants")) EXPECT_EQ(g, 0.0);
  for (const double g : fronts.column("closings_on_fronts")) EXPECT_EQ(g, 0.0);
  // The perturbed orbits over 1000 periods: K's Jordan block at -1 (defect 1, from the closed
  // form's fronts) allows a drift linear in k, no exponential growth: a power of k under 1.5
  // (|mu| = 1.005 would read 3) and under 1e3-fold (|mu| = 1.007 would pass it).
  const auto largest = fronts.column("growth_largest"), power = fronts.column("growth_power");
  for (std::size_t i = 0; i < largest.size(); ++i) {
    EXPECT_LT(largest[i], 1e3) << i;
    EXPECT_LT(power[i], 1.5) << i;
  }
}

// Mode 1's K is [1], with its eigenvector: a perturbed orbit stays within a few times its size
// (measured at most 1.8 over 1000 periods on the closed forms, test_monodromy.cpp).
TEST(StabilityFiles, PerturbedModeOneOrbitsStayNear) {
  const fs::path out = cli::scratch("stability_cli", "bar_mode1_growth");
  const cli::Run r = cli::run(
      "trace", paper + " --branch mode1 --shooting_elements 20 --max_points 6 --stability true",
      out);
  ASSERT_EQ(r.code, 0) << r.err;
  const backbone::core::Table fronts = backbone::core::Table::read_csv(out / "fronts.csv");
  ASSERT_GT(fronts.rows(), 0u);
  for (const double g : fronts.column("growth_largest")) EXPECT_LT(g, 5.0);
  fs::remove_all(out);
}

// The subharmonic continuum at one energy starts on a grazing limit (shape 1: the end touches
// the wall once without a phase, as a front arrives): fronts.csv's grazing_instants and
// closings_on_fronts, by the exact solver, say 1 there and 0 inside, where the TD-BEM's one-sided
// differences agree (tdbem_kink of order 1 on the grazing, round-off inside: below 1e-3, the
// threshold the verdict takes).
TEST(StabilityFiles, TheContinuumsGrazingLimitIsFlaggedWithoutTheTdbem) {
  const fs::path out = cli::scratch("stability_cli", "continuum_grazing");
  const cli::Run r = cli::run("trace",
                              paper +
                                  " --branch subharmonic_continuum --energy 1e-3 "
                                  "--shooting_elements 20 --stability true "
                                  "--stability_tdbem_check true",
                              out);
  ASSERT_EQ(r.code, 0) << r.err;
  const backbone::core::Table fronts = backbone::core::Table::read_csv(out / "fronts.csv");
  ASSERT_GT(fronts.rows(), 10u);
  const auto grazing = fronts.column("grazing_instants"), kink = fronts.column("tdbem_kink");
  const auto on_fronts = fronts.column("closings_on_fronts");
  EXPECT_EQ(grazing[0], 1.0);
  EXPECT_EQ(on_fronts[0], 1.0);
  EXPECT_GT(kink[0], 0.1);
  for (std::size_t i = 1; i < grazing.size(); ++i) {
    EXPECT_EQ(grazing[i], 0.0) << i;
    EXPECT_EQ(on_fronts[i], 0.0) << i;
    EXPECT_LT(kink[i], 1e-3) << i;
  }
  // The perturbed orbits, the check where K is one side's: the grazing orbit's end starts on
  // the wall, and the draw that would push it through is projected onto the wall, so every
  // point has the check. Every K here, the grazing end's one-sided one too, has its multipliers
  // on the circle and Jordan defect at most 1: a drift at most linear (power <= 1.5).
  const auto largest = fronts.column("growth_largest"), power = fronts.column("growth_power");
  for (std::size_t i = 0; i < largest.size(); ++i) {
    EXPECT_TRUE(std::isfinite(largest[i])) << i;
    EXPECT_LT(power[i], 1.5) << i;
  }
  fs::remove_all(out);
}

// summary.txt counts the points by stability, the followed branches' too. Mode 1 has one
// front and K = [1] (problems/contact_bar/orbits/README.md, 'Stability'): every point of the
// branch is stable. The followed families attached to it: each of their points is counted once.
TEST(StabilityFiles, SummariesCountThePointsByStability) {
  const fs::path out = cli::scratch("stability_cli", "counts");
  const cli::Run r = cli::run("trace",
                              paper +
                                  " --branch mode1 --shooting_elements 40 --period 3.1 --ds 0.05 "
                                  "--ds_max 0.05 --max_points 60 --detect_branch_points true "
                                  "--follow all --follow_max_points 4 --stability true "
                                  "--stability_growth_periods 0",
                              out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto value = [](const fs::path& dir, const char* key) {
    return backbone::core::read_text_value(dir / "summary.txt", key);
  };
  EXPECT_EQ(value(out, "stable_points"), "60");
  EXPECT_EQ(value(out, "unstable_points"), "0");
  EXPECT_EQ(value(out, "undecided_points"), "0");
  int followed = 0;
  const std::size_t rows = backbone::core::Table::read_csv(out / "branch_points.csv").rows();
  for (std::size_t k = 1; k <= rows; ++k) {
    const fs::path dir = out / ("branch_point_" + std::to_string(k));
    if (!fs::exists(dir / "branch.csv")) continue;
    ++followed;
    const auto stable = backbone::core::Table::read_csv(dir / "branch.csv").column("stable");
    const long counted = std::stol(value(dir, "stable_points")) +
                         std::stol(value(dir, "unstable_points")) +
                         std::stol(value(dir, "undecided_points"));
    EXPECT_EQ(counted, static_cast<long>(stable.size())) << k;
    EXPECT_EQ(value(dir, "stable_points"),
              std::to_string(std::count(stable.begin(), stable.end(), 1.0)))
        << k;
  }
  EXPECT_GE(followed, 4);
  fs::remove_all(out);
}

TEST(StabilityInput, TdbemCheckNeedsTheTdbemAndTheFronts) {
  cli::expect_bad_input("trace",
                        paper +
                            " --branch mode1 --stability true --stability_tdbem_check true "
                            "--stability_representation grid",
                        "stability_tdbem_check", "stability_cli");
  cli::expect_bad_input("trace", paper + " --branch mode1 --stability_tdbem_check true",
                        "stability_tdbem_check", "stability_cli");
}
