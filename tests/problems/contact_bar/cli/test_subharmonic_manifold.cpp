// `backbone trace ... --branch subharmonic_manifold`: the atlas of the subharmonic manifold
// (problems/contact_bar/orbits/manifold.hpp) on a small energy range at N = 20, checked
// against the closed forms of family.hpp (period 2 T2 whatever the shape) and the exact oracle
// (return_error in manifold.csv), its extent against the bounds, its neighbours for symmetry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

using backbone::core::Table;

std::vector<int> split(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ';'))
    if (!item.empty()) out.push_back(std::stoi(item));
  return out;
}

// Tolerances: the period is fixed by the closed form to round-off, 1e-8 is the acceptance; the
// exact return of exactly represented members is round-off too, 1e-6 is the return_tolerance
// every chart passes.
TEST(SubharmonicManifoldCli, CoversTheEnergyRangeAndBothGrazingSides) {
  const std::string scene =
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
  const auto out = cli::scratch("subharmonic_manifold", "small");
  const cli::Run r = cli::run("trace",
                              scene +
                                  " --branch subharmonic_manifold --energy_min 1e-5 --energy_max "
                                  "3e-5 --shooting_elements 20 --chart_radius 0.3",
                              out);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(out / "manifold.png"));
  const Table m = Table::read_csv(out / "manifold.csv");
  ASSERT_GE(m.rows(), 5u);
  const auto energy = m.column("energy"), shape = m.column("shape");
  const auto period_error = m.column("period_error"), returns = m.column("return_error");
  const auto neighbours = m.text_column("neighbours");
  for (std::size_t i = 0; i < m.rows(); ++i) {
    EXPECT_GE(energy[i], 1e-5 * (1 - 1e-12)) << i;
    EXPECT_LE(energy[i], 3e-5 * (1 + 1e-12)) << i;
    EXPECT_GE(shape[i], 1e-3 - 1e-9) << i;  // the shape window [shape_margin, 1 - shape_margin]
    EXPECT_LE(shape[i], 1 - 1e-3 + 1e-9) << i;
    EXPECT_LT(std::abs(period_error[i]), 1e-8) << i;
    EXPECT_LT(returns[i], 1e-6) << i;
    const std::vector<int> mine = split(neighbours[i]);
    EXPECT_FALSE(mine.empty()) << i;
    for (int j : mine) {
      ASSERT_LT(static_cast<std::size_t>(j), m.rows());
      const std::vector<int> theirs = split(neighbours[static_cast<std::size_t>(j)]);
      EXPECT_NE(std::find(theirs.begin(), theirs.end(), static_cast<int>(i)), theirs.end())
          << i << " -> " << j;
    }
  }
  // The atlas reaches the bounds: bisection places boundary charts within 1/64 of a step of
  // them (energies within a few percent, shapes near the grazing sides 0 and 1).
  EXPECT_LT(*std::min_element(energy.begin(), energy.end()), 1.05e-5);
  EXPECT_GT(*std::max_element(energy.begin(), energy.end()), 2.85e-5);
  EXPECT_LT(*std::min_element(shape.begin(), shape.end()), 0.05);
  EXPECT_GT(*std::max_element(shape.begin(), shape.end()), 0.95);
}

}  // namespace
