// The Duffing benchmark against AUTO-07p (problems/duffing/bench/bench.hpp): backbone's headline
// run against the exact period, the reader of AUTO's branch file on a file with known errors, and
// the stored peer runs against the exact period recomputed here.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>

#include "core/errors.hpp"
#include "core/io/table.hpp"
#include "problems/duffing/bench/bench.hpp"
#include "problems/duffing/duffing.hpp"

using namespace backbone;

namespace {

std::filesystem::path scratch_folder(const std::string& name) {
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() /
      ("backbone_test_duffing_bench_" + name + "_" +
       std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

}  // namespace

// The bench's default settings (rtol 1e-12, ds_max 1) reach amplitude 5 within the error bound
// 4e-11 of the exact period (the AUTO-07p NTST 50 error, 4.3e-11, rounded down). The residual
// tolerance 1e-11 alone allows dT / T <= 1e-11 / 3, CVODE at rtol 1e-12 adds ~1e-12 per flow, so a
// bound of 4e-11 is met with a margin and a broken Jacobian, step or tolerance (errors 1e-9 and up)
// fails it.
TEST(DuffingBench, HeadlineRunReachesAmplitudeFiveWithinTheErrorTarget) {
  const duffing::BackboneSettings settings;
  const duffing::BackboneRun run = duffing::trace_backbone(settings);
  ASSERT_TRUE(run.complete) << run.message;
  EXPECT_LE(run.max_error, 4e-11);
  EXPECT_GT(run.points, 2);
  std::cout << "[ measured ] " << run.points << " points, max error " << run.max_error << ", "
            << run.seconds << " s, " << run.residuals << " residuals\n";
}

// A branch file in AUTO's layout: two header rows, the Hopf point (H = 0, skipped), one point
// printed at the exact period and one 1e-6 off. AUTO prints 11 digits, so the exact point's
// error is below 1e-10 and the maximum is the planted 1e-6 (to the print precision).
TEST(DuffingBench, AutoBranchReaderMeasuresThePlantedError) {
  const std::filesystem::path folder = scratch_folder("reader");
  const auto row = [](int point, double energy, double period) {
    return fmt::format(
        "  -2  {:4d}   0    0  1.0E-015  1.0E+000  1.0E+000  1.0E+000  {:.10E}  {:.10E}  "
        "1.0E+000  1.0E+000\n",
        point, period, energy);
  };
  const double h1 = 0.75, h2 = 168.75;  // amplitudes 1 and 5: A^2/2 + A^4/4
  {
    std::ofstream out(folder / "b.duffing");
    out << "   0   EPSL= 1.0000E-10  EPSU = 1.0000E-10  EPSS = 1.0000E-06\n"
        << "   0    PT  TY  LAB       mu    L2-NORM    MAX x    MAX v    PERIOD    H    A    AH\n"
        << row(1, 0.0, 2 * std::numbers::pi) << row(2, h1, duffing::exact_period(1.0))
        << row(3, h2, duffing::exact_period(5.0) * (1 + 1e-6));
  }
  const duffing::AutoRun run = duffing::read_auto07p_branch(folder / "b.duffing");
  EXPECT_EQ(run.points, 2);
  EXPECT_NEAR(run.max_error, 1e-6, 1e-10);
  std::filesystem::remove_all(folder);
  EXPECT_THROW(duffing::read_auto07p_branch(folder / "b.duffing"), core::InputError);
}

// The stored AUTO-07p runs (problems/duffing/peers) against the exact period recomputed here from
// each point's energy: the stored T_exact column agrees with exact_period to its 13 printed
// digits (5e-13 relative), and the summary of auto07p_runs.csv is the maximum of the branch.
TEST(DuffingBench, StoredAutoRunsAgreeWithTheExactPeriod) {
  const std::vector<duffing::AutoRun> runs = duffing::stored_auto07p_runs();
  ASSERT_EQ(runs.size(), 2u);
  for (const duffing::AutoRun& stored : runs) {
    const core::Table t = core::Table::read_csv(
        duffing::peers_folder() / fmt::format("duffing_ntst{}_backbone.csv", stored.ntst));
    const std::vector<double> energy = t.column("H"), period = t.column("T_auto"),
                              exact = t.column("T_exact");
    double worst = 0;
    for (std::size_t i = 0; i < t.rows(); ++i) {
      const double amplitude = std::sqrt(std::sqrt(1 + 4 * energy[i]) - 1);
      const double mine = duffing::exact_period(amplitude);
      EXPECT_NEAR(exact[i], mine, 5e-13 * mine) << "row " << i;
      worst = std::max(worst, std::abs(period[i] - mine) / mine);
    }
    EXPECT_EQ(stored.points, static_cast<int>(t.rows()));
    // The summary has 4 digits (5e-4 relative); worst moves by up to the 5e-13 of T_exact.
    EXPECT_NEAR(stored.max_error, worst, 1e-3 * worst + 1e-12) << "NTST " << stored.ntst;
  }
}
