// What the contact-bar figure jobs read from trace outputs
// (problems/contact_bar/figures/modes.hpp), on small hand-written branch folders: which orbit is
// drawn, and the closed-form summary.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/io/table.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/figures/stability.hpp"

namespace {

namespace fs = std::filesystem;
using namespace backbone;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(BACKBONE_BINARY_DIR) / "test_output" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// Three orbits at E = 1e-4, 1e-3, 1e-2 J, u0 on the nodes x = 0.5, 1 (orbits.csv omits x = 0).
void write_branch(const fs::path& dir) {
  write(dir / "branch.csv",
        "point,period,energy,jacobian_evaluations\n0,3.9,1e-4,5\n1,3.5,1e-3,2\n2,3.2,1e-2,1\n");
  write(dir / "orbits.csv", "point,x,u0\n0,0.5,-1\n0,1,-2\n1,0.5,-3\n1,1,-6\n2,0.5,-10\n2,1,-20\n");
}

TEST(ContactBarFigures, LoadsTheOrbitNearestTheEnergyAndPutsBackTheFixedEnd) {
  const fs::path dir = fresh_dir("figures_load") / "mode1";
  write_branch(dir);
  // Default: the geometric middle of the energy range, 1e-3 J.
  const auto middle = contact_bar::load_traced_orbit(dir, 0, 1.0);
  ASSERT_TRUE(middle.has_value());
  EXPECT_EQ(middle->energy, 1e-3);
  EXPECT_EQ(middle->period, 3.5);
  ASSERT_EQ(middle->u0.knots().size(), 3u);
  EXPECT_EQ(middle->u0(0.0), 0.0);
  EXPECT_EQ(middle->u0(0.5), -3.0);
  EXPECT_EQ(middle->u0(1.0), -6.0);
  // Nearest in log energy: 5e-3 is closer to 1e-2 than to 1e-3.
  EXPECT_EQ(contact_bar::load_traced_orbit(dir, 5e-3, 1.0)->energy, 1e-2);
  // Knots beyond the bar length are clipped to it.
  EXPECT_EQ(contact_bar::load_traced_orbit(dir, 1e-4, 0.8)->u0.knots().back(), 0.8);
  EXPECT_FALSE(contact_bar::load_traced_orbit(dir.parent_path() / "mode2", 0, 1.0).has_value());
}

TEST(ContactBarFigures, ClosedFormSummaryHasOneRowPerCheckedBranch) {
  const fs::path out = fresh_dir("figures_summary");
  for (const char* name : {"mode2", "mode1"}) {
    write_branch(out / name);
    write(out / name / "closed_form_check.csv",
          "point,energy,relative_error,return_error_u,return_error_v\n"
          "0,1e-4,1e-14,2e-13,3e-10\n1,1e-3,5e-14,1e-13,1e-10\n2,1e-2,2e-14,4e-13,2e-10\n");
  }
  write_branch(out / "duffing");  // no closed_form_check.csv: not a contact-bar branch
  ASSERT_EQ(contact_bar::write_closed_form_summary(out), 0);
  std::ifstream in(out / "closed_form_summary.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "branch,points,energy_first,energy_last,worst_relative_error,worst_return_error_u,"
            "worst_return_error_v,jacobian_evaluations");
  // Sorted by name; worst = maximum over points; jacobian_evaluations = their sum over the
  // branch (branch.csv).
  // Numbers are written with 17 digits: they read back exactly.
  for (const char* name : {"mode1", "mode2"}) {
    ASSERT_TRUE(std::getline(in, line));
    std::stringstream row(line);
    std::vector<std::string> cells;
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 8u);
    EXPECT_EQ(cells[0], name);
    const std::vector<double> expected{3, 1e-4, 1e-2, 5e-14, 4e-13, 3e-10, 8};
    for (std::size_t k = 0; k < expected.size(); ++k)
      EXPECT_EQ(std::stod(cells[k + 1]), expected[k]) << name << " column " << k + 1;
  }
  EXPECT_FALSE(std::getline(in, line));
}

// The verdict follows the fronts' K only where the period map has a derivative: multipliers off
// the circle at points on a kink (one side's K) make no "unstable", they are said unresolved;
// one such point off the kinks does. The grid gives no verdict.
TEST(ContactBarFigures, TheStabilityVerdictLeavesTheKinksUnresolved) {
  using backbone::contact_bar::stability_verdict;
  const std::string on_kinks = stability_verdict("fronts", 2, 2, 0, 0, 1, 7);
  EXPECT_EQ(on_kinks.find("unstable at"), std::string::npos) << on_kinks;
  EXPECT_NE(on_kinks.find("at 2 points on a kink one side's K has one: not resolved"),
            std::string::npos)
      << on_kinks;
  EXPECT_NE(on_kinks.find("(7 points on a kink of the period map"), std::string::npos);
  const std::string off = stability_verdict("fronts", 3, 2, 0, 0, 1, 7);
  EXPECT_EQ(off.find("unstable at 1 point "), 0u) << off;
  EXPECT_EQ(stability_verdict("fronts", 0, 0, 0, 1, 1, 0).find("Jordan defect 1:"),
            std::string("no multiplier off the unit circle; ").size());
  EXPECT_EQ(stability_verdict("grid", 5, 0, 0, 0, 0, 0).find("projected grid: no verdict"), 0u);
}

// On a kink the perturbed orbits decide what one side's K cannot: with a drift at most linear
// (power <= 1.5) the verdict gives their bound on the excited multipliers; a faster growth
// leaves the point unresolved.
TEST(ContactBarFigures, TheKinksVerdictFollowsThePerturbedOrbits) {
  using backbone::contact_bar::KinkGrowth;
  using backbone::contact_bar::stability_verdict;
  const std::string linear =
      stability_verdict("fronts", 2, 2, 0, 0, 1, 7, KinkGrowth{1000, 192, 0.99, 1.36});
  // 192^(1 / 1000) = 1.00527: the bound on every excited multiplier.
  EXPECT_NE(linear.find("(|mu| up to 1.36), but a perturbed orbit there grows like k^0.99, at "
                        "most 192-fold over 1000 periods: no excited |mu| above 1.005"),
            std::string::npos)
      << linear;
  EXPECT_EQ(linear.find("unstable at"), std::string::npos) << linear;
  const std::string faster =
      stability_verdict("fronts", 2, 2, 0, 0, 1, 7, KinkGrowth{1000, 5e4, 3.1, 1.36});
  EXPECT_NE(faster.find("and a perturbed orbit grows like k^3.10: not resolved there"),
            std::string::npos)
      << faster;
}

}  // namespace
