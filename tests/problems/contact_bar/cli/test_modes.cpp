// `backbone trace ... --branch modeJ` for J >= 3 (problems/contact_bar/orbits/README.md, section
// 'Mode J'): from grazing to the energy bound, dimension 1 at every point, each point against
// the closed form at its own energy and against the exact oracle (closed_form_check.csv).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <numeric>
#include <string>

#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

using backbone::core::Table;

// `backbone trace` on the paper scene with these arguments, into out.
cli::Run trace_paper(const std::string& arguments, const std::filesystem::path& out) {
  return cli::run(
      "trace",
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini " + arguments,
      out);
}

// Tolerances: the frequency is the closed form's to the Newton tolerance (1e-10 relative to the
// amplitude; measured at most 2.5e-13), 1e-10 leaves a margin; the exact-oracle return is the
// trace's own return_tolerance 1e-6 (measured at most 1.7e-9).
TEST(ModesCli, ModesThreeAndEightReachTheEnergyBoundAlongTheirClosedForms) {
  for (int mode : {3, 8}) {
    const auto out = cli::scratch("modes", "mode" + std::to_string(mode));
    const cli::Run r = trace_paper("--branch mode" + std::to_string(mode), out);
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
  const auto out = cli::scratch("modes", "refused");
  cli::Run r = trace_paper("--branch mode11", out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("shooting_elements"), std::string::npos) << r.err;
  for (const char* bad : {"mode0", "mode03", "modex", "mode-1"}) {
    r = trace_paper(std::string("--branch ") + bad, out);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.err.find("modeJ for every J >= 1"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(out / "branch.csv"));
}

}  // namespace

namespace {

// The law of the families attached to mode 1 (problems/contact_bar/orbits/README.md, section
// 'Attached families: the law'): a branch point lies at T = 2q L / (p c) with p/q in lowest
// terms, at E = EA p^2 g0^2 / (2L (2q - 3p)^2); a grid of N intervals verifies it iff p divides
// 2N (and 2N/p >= 3), with attached dimension ceil(N/p) - 1. Every candidate the detection
// locates on mode 1 at 40 intervals up to 3e-5 J is checked against it, and verified exactly
// when p divides 80. A verified one lies at 2q/p to 1e-12 relative: the location finds the
// root again on points whose components along the attached directions are the branch's
// (locator.cpp, refine_on_branch); measured at most 1.0e-13 (T = 3.5), where the root on the
// points the location corrected lies 2e-9 off (T = 3.6) on these steps of 0.05 of the
// amplitude.
TEST(ModesCli, TheBranchPointsOfModeOneFollowTheLawOfAttachedPeriods) {
  const auto out = cli::scratch("modes", "law");
  const cli::Run r = trace_paper(
      "--branch mode1 --shooting_elements 40 --energy_max 3e-5 "
      "--detect_branch_points true",
      out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table b = Table::read_csv(out / "branch_points.csv");
  const auto period = b.column("period"), energy = b.column("energy"),
             verified = b.column("verified"), dimension = b.column("dimension"),
             wavenumber = b.column("content_wavenumber"), order = b.column("resonance_order");
  ASSERT_GE(period.size(), 3u);
  const int n = 40;
  int checked = 0;
  for (std::size_t i = 0; i < period.size(); ++i) {
    // The nearest 2q/p with p <= 60 (c = L = 1 on the paper scene).
    int best_p = 0, best_q = 0;
    double best = 1e300;
    for (int p = 1; p <= 60; ++p) {
      const int q = static_cast<int>(std::lround(period[i] * p / 2));
      if (std::gcd(p, q) != 1) continue;
      const double d = std::abs(period[i] - 2.0 * q / p);
      if (d < best) best = d, best_p = p, best_q = q;
    }
    const bool divides = (2 * n) % best_p == 0 && 2 * n / best_p >= 3;
    if (verified[i] == 1) {
      EXPECT_LT(best / period[i], 1e-12) << "T " << period[i];
      EXPECT_TRUE(divides) << "T " << period[i] << " p " << best_p;
      EXPECT_EQ(dimension[i], (n + best_p - 1) / best_p - 1) << "T " << period[i];
      const double g0 = 1e-3, k = 2.0 * best_q - 3.0 * best_p;
      EXPECT_NEAR(energy[i] / (best_p * best_p * g0 * g0 / (2 * k * k)), 1, 1e-6);
      // The measured content (attached_content.hpp): its wavenumber is p and its resonance
      // order p T / 2 is q, to the location's 1e-8 of T.
      EXPECT_EQ(wavenumber[i], best_p) << "T " << period[i];
      EXPECT_NEAR(order[i], best_q, 1e-6) << "T " << period[i];
      ++checked;
    } else {
      EXPECT_FALSE(divides && best < 1e-7) << "an unverified candidate on the law: T " << period[i];
    }
  }
  EXPECT_GE(checked, 2);
}

// With the exact Jacobian the location takes its test function down to round-off
// (continuation/README.md, 'Branch points'): on steps of 0.1 % of the amplitude every verified
// branch point of mode 1 at 40 intervals up to 1.3e-5 J (T = 3.9 to 3.2, 13 families) lies at
// the law's 2q/p. Measured: at most 1.6e-13 relative (T = 3.5). Without refine_on_branch the
// root lies up to 5.9e-10 off (T = 3.75), and as far without the polishing chord steps of the
// location's evaluations. The bound 5e-12 tells them apart with a margin.
TEST(ModesCli, WithTheExactJacobianTheBranchPointsSitAtTheLawsPeriods) {
  const auto out = cli::scratch("modes", "law_located");
  const cli::Run r = trace_paper(
      "--branch mode1 --shooting_elements 40 --energy_max 1.3e-5 --detect_branch_points true "
      "--ds 0.001 --ds_max 0.001 --max_points 8000",
      out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table b = Table::read_csv(out / "branch_points.csv");
  const auto period = b.column("period"), verified = b.column("verified"),
             wavenumber = b.column("content_wavenumber"), order = b.column("resonance_order");
  int checked = 0;
  for (std::size_t i = 0; i < period.size(); ++i) {
    if (verified[i] != 1) continue;
    const double law = 2.0 * std::lround(order[i]) / wavenumber[i];
    EXPECT_LT(std::abs(period[i] / law - 1), 5e-12) << "T " << period[i] << " law " << law;
    ++checked;
  }
  EXPECT_EQ(checked, 13);
}

// A followed attached family ends at its boundary, and the run says so with exit 0. At 10
// intervals the family attached at T = 16/5 (p = 5) has dimension ceil(10/5) - 1 = 1: warps
// whose X - x is the one content sin(5 pi x) the grid holds, sampled at its nodes as 0, +-1,
// so X' = 1 +- a on alternate pairs of intervals and E / E_pq = 1 + a^2. The family ends where
// X' = 1 - a vanishes (orbits/README.md, 'Attached families: the law'): at E = 2 E_pq =
// 2.5e-5 J, with min_slope 0 there. The path's last point stops within the boundary's 1e-3 of
// it, so its energy is 2 E_pq to 1e-3 (measured: 2e-8), at a period held to 1e-9.
TEST(ModesCli, AFollowedFamilyEndsAtItsBoundary) {
  const auto out = cli::scratch("modes_cli", "family_boundary");
  const cli::Run r = trace_paper(
      "--branch mode1 --shooting_elements 10 "
      "--detect_branch_points true --follow all --energy_max 3e-5",
      out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table points = Table::read_csv(out / "branch_points.csv");
  const auto period = points.column("period"), verified = points.column("verified");
  int followed = 0;
  for (std::size_t i = 0; i < period.size(); ++i) {
    if (verified[i] != 1) continue;
    ASSERT_NEAR(period[i], 3.2, 1e-7);
    const auto dir = out / ("branch_point_" + std::to_string(i + 1));
    const Table b = Table::read_csv(dir / "branch.csv");
    const auto energy = b.column("energy"), slope = b.column("min_slope");
    const auto branch_period = b.column("period");
    EXPECT_NEAR(energy.back() / 2.5e-5, 1, 1e-3);
    EXPECT_LE(slope.back(), 1e-3);
    for (double t : branch_period) EXPECT_NEAR(t / 3.2, 1, 1e-9);
    std::ifstream in(dir / "summary.txt");
    const std::string summary((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(summary.find("stop_reason boundary_reached"), std::string::npos) << summary;
    ++followed;
  }
  EXPECT_EQ(followed, 1);
}

// Along a followed family every rank check reads the law's dimension ceil(N/p) - 1, on its
// faces too (min_slope 0 on an interval: J there is the outside's, orbits/README.md 'Attached
// families: the law', verified just inside with dimension_flag 3). Mode 1 at 40 intervals up
// to 3e-5 J, every verified family followed for 21 points (rank checks at points 0, 10, 20);
// the case holds such points (checked), where J alone reads 2 for 4 and 5 for 7.
TEST(ModesCli, EveryRankCheckAlongAFollowedFamilyReadsTheLawsDimension) {
  const auto out = cli::scratch("modes_cli", "follow_dimension");
  const int n = 40;
  const cli::Run r = trace_paper(
      "--branch mode1 --shooting_elements 40 --detect_branch_points true --ds 0.05 --ds_max 0.05 "
      "--energy_max 3e-5 --follow all --follow_max_points 21",
      out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table points = Table::read_csv(out / "branch_points.csv");
  const auto period = points.column("period"), verified = points.column("verified");
  int inside = 0, followed = 0;
  for (std::size_t i = 0; i < period.size(); ++i) {
    if (verified[i] != 1) continue;
    int p = 1;  // 2/T = p/q in lowest terms (c = L = 1)
    while (p <= 60 && std::abs(period[i] * p / 2 - std::round(period[i] * p / 2)) > 1e-6) ++p;
    ASSERT_LE(p, 60) << "T " << period[i] << " is no 2q/p with p <= 60";
    const int law = (n + p - 1) / p - 1;
    const Table b = Table::read_csv(out / ("branch_point_" + std::to_string(i + 1)) / "branch.csv");
    const auto dimension = b.column("dimension"), flag = b.column("dimension_flag");
    int flagged = 0;
    for (std::size_t k = 0; k < dimension.size(); ++k) {
      if (dimension[k] < 0) continue;  // no rank check at this point
      EXPECT_EQ(dimension[k], law) << "T " << period[i] << " point " << k;
      if (flag[k] == 3) ++flagged;
    }
    // The follow's summary.txt counts them.
    std::ifstream summary(out / ("branch_point_" + std::to_string(i + 1)) / "summary.txt");
    const std::string text{std::istreambuf_iterator<char>(summary), {}};
    EXPECT_NE(text.find("\ndimension_inside " + std::to_string(flagged) + "\n"), std::string::npos)
        << text;
    // inspect at the first flagged point says what branch.csv holds there.
    for (std::size_t k = 0; k < dimension.size() && inside == 0 && flagged > 0; ++k) {
      if (flag[k] != 3) continue;
      const auto report = out / ("inspect_" + std::to_string(i + 1) + ".txt");
      const std::string command =
          std::string("'") + BACKBONE_BINARY_DIR + "/bin/backbone' inspect '" +
          (out / "scene.ini").string() + "' --orbit '" +
          (out / ("branch_point_" + std::to_string(i + 1)) / "orbits.csv").string() + ":" +
          std::to_string(k) + "' > '" + report.string() + "'";
      EXPECT_EQ(std::system(command.c_str()), 0) << command;
      EXPECT_NE(cli::file_text(report).find("branch.csv: dimension " + std::to_string(law) +
                                            " at this point, verified at a neighbour just inside"),
                std::string::npos)
          << cli::file_text(report);
    }
    inside += flagged;
    ++followed;
  }
  EXPECT_GE(followed, 2);
  EXPECT_GE(inside, 2) << "no rank check verified inside: the case tests nothing";
}

// The law on modes 2 and 3 (orbits/README.md, 'Attached families: the law'): mode J's branch
// points lie at T = 2q/p with strain s = g0 p / (2 J^2 q - (2J + 1) p) and kinks at multiples
// of L/p; a grid of N intervals with p | 2N whose knots' reference nodes sit on the kinks
// there (uniform at the branch point) verifies the family, of dimension ceil(N/p) - 1. Mode 2
// at T = 9/7 (p = 14, q = 9: s = 7 g0, crest at 2/7 L) on 35 intervals, knot node 10, and at
// T = 14/11 (p = 11, q = 7: s = 11 g0) on 77, knot node 21; mode 3 at T = 18/23 (p = 23,
// q = 9: s = 23 g0, kinks at 5/23 and 13/23) on 46, nodes 10 and 26. Located at 2q/p to 1e-12
// relative (measured at most 5.7e-16; the root on the points the location corrected lies
// 1.1e-11 to 1.6e-10 off: locator.cpp, refine_on_branch), energy EA L s^2 / 2 to 1e-6.
TEST(ModesCli, TheLawLocatesTheFamiliesAttachedToModesTwoAndThree) {
  struct Case {
    const char* branch;
    int elements;
    const char* knots;
    const char* energy_max;
    int mode, p, q;
  };
  for (const Case& c :
       {Case{"mode2", 35, "10", "4e-5", 2, 14, 9}, Case{"mode2", 77, "21", "1e-4", 2, 11, 7},
        Case{"mode3", 46, "10,26", "4e-4", 3, 23, 9}}) {
    const auto out = cli::scratch(
        "modes_cli", std::string("law_") + c.branch + "_" + std::to_string(c.elements));
    const cli::Run r = trace_paper(
        std::string("--branch ") + c.branch + " --shooting_elements " + std::to_string(c.elements) +
            " --knot_nodes " + c.knots +
            " --detect_branch_points true --amplitude_units false --ds 0.05 --ds_max 0.05 "
            "--energy_max " +
            c.energy_max + " --follow all",
        out);
    ASSERT_EQ(r.code, 0) << r.err;
    const Table points = Table::read_csv(out / "branch_points.csv");
    const auto period = points.column("period"), energy = points.column("energy");
    const auto verified = points.column("verified"), dimension = points.column("dimension");
    const double t = 2.0 * c.q / c.p, g0 = 1e-3;
    const double s = g0 * c.p / (2.0 * c.mode * c.mode * c.q - (2.0 * c.mode + 1) * c.p);
    int found = 0;
    for (std::size_t i = 0; i < period.size(); ++i) {
      if (verified[i] != 1) continue;
      EXPECT_LT(std::abs(period[i] / t - 1), 1e-12) << c.branch << " " << c.elements;
      EXPECT_NEAR(energy[i] / (0.5 * s * s), 1, 1e-6) << c.branch;
      EXPECT_EQ(dimension[i], (c.elements + c.p - 1) / c.p - 1) << c.branch;
      const Table followed =
          Table::read_csv(out / ("branch_point_" + std::to_string(i + 1)) / "branch.csv");
      for (double tf : followed.column("period")) EXPECT_NEAR(tf / t, 1, 1e-9) << c.branch;
      EXPECT_GE(followed.rows(), 2u);
      ++found;
    }
    EXPECT_EQ(found, 1) << c.branch;
  }
}

// The attached dimension is counted by probing each candidate direction, at most max_probes of
// them. At 200 intervals the family at T = 7/2 (p = 4) has dimension ceil(200/4) - 1 = 49 by the
// law: the default 24 probes give a lower bound the row says is one (probed < candidates), 60
// probes give the law's number.
TEST(ModesCli, TheAttachedDimensionReachesTheLawWithEnoughProbes) {
  for (const int probes : {24, 60}) {
    const auto out = cli::scratch("modes_cli", "probes_" + std::to_string(probes));
    const cli::Run r = trace_paper(
        "--branch mode1 --shooting_elements 200 "
        "--detect_branch_points true --energy_max 2.5e-6 "
        "--max_probes " +
            std::to_string(probes),
        out);
    ASSERT_EQ(r.code, 0) << r.err;
    const Table points = Table::read_csv(out / "branch_points.csv");
    const auto period = points.column("period"), dimension = points.column("dimension");
    const auto candidates = points.column("candidates"), probed = points.column("probed");
    int found = 0;
    for (std::size_t i = 0; i < period.size(); ++i) {
      if (std::abs(period[i] - 3.5) > 1e-7) continue;
      ++found;
      EXPECT_EQ(candidates[i], 49);
      EXPECT_EQ(probed[i], std::min(49, probes));
      EXPECT_EQ(dimension[i], std::min(49, probes));
    }
    EXPECT_EQ(found, 1) << probes;
  }
}

}  // namespace
