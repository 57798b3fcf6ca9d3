// The branch figure plots every row of branch.csv: it once dropped the first point (a `skip 1`
// added to a script whose header gnuplot already reads with `columnhead`). The oracle is gnuplot
// itself: the script of continuation::branch_plot_script, run with the settings of
// core::render_png but on the `unknown` terminal, reports the data range it plotted
// (GPVAL_DATA_X_MIN / _MAX); the smallest energy is in the first row only, so a script that
// skips that row reports the second row's energy.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "continuation/outputs.hpp"
#include "core/io/table.hpp"

namespace fs = std::filesystem;

TEST(BranchPlot, ScriptPlotsTheFirstRow) {
  // gnuplot is a required package (.ci/install installs gnuplot-nox): its absence is a failure.
  ASSERT_EQ(std::system("gnuplot --version > /dev/null 2>&1"), 0) << "gnuplot not found";
  const fs::path dir = fs::path(BACKBONE_BINARY_DIR) / "tests" / "branch_plot";
  fs::create_directories(dir);
  backbone::core::Table t({"point", "period", "frequency", "energy"});
  t.add_row({0, 3.9, 1.61, 1e-6});  // the first row: the smallest and the largest values
  t.add_row({1, 3.5, 1.80, 2e-5});
  t.add_row({2, 3.2, 1.96, 4e-4});
  t.add_row({3, 3.1, 2.03, 1e-5});
  t.write_csv(dir / "branch.csv");
  const std::string script = backbone::continuation::branch_plot_script(dir / "branch.csv", t, "t");
  ASSERT_FALSE(script.empty());
  {
    std::ofstream gp(dir / "check.gp");
    gp << "set terminal unknown\nset datafile separator ','\nset key autotitle columnhead\n"
       << script
       << "set print '-'\nprint sprintf('%.6g %.6g', GPVAL_DATA_X_MIN, GPVAL_DATA_Y_MIN)\n";
  }
  const std::string command = "gnuplot '" + (dir / "check.gp").string() + "' 2>/dev/null";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char line[256] = {};
  std::string out;
  while (std::fgets(line, sizeof line, pipe)) out += line;
  pclose(pipe);
  // x: energy (log axis), y: frequency; both minima are in the first row.
  EXPECT_EQ(out, "1e-06 1.61\n") << script;
  fs::remove_all(dir);
}
