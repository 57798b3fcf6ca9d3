// `backbone trace --detect_branch_points true` end to end on the contact bar: branch_points.csv
// has the documented columns and holds the branch point of mode 1 at T = 3.2 L/c, located at the
// exact value; `--follow` switches onto the attached family there and writes its branch.
//
// At shooting_elements 40 and E <= 3e-5 the run is short and finds two candidates: a dip near
// T = 3.33 that its probes do not verify, and T = 3.2 with an attached family of dimension 6 or
// 7 (it depends on N and on round-off, problems/contact_bar/orbits/README.md, 'Dimension changes').
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.hpp"
#include "core/io/scene_ini.hpp"
#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using backbone::core::Table;

const std::string paper =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
const std::string detecting =
    paper + " --branch mode1 --shooting_elements 40 --energy_max 3e-5 --detect_branch_points true";

// 60 points of mode 1 from T = 3.1 at 40 intervals, following its branch points: about 1 s.
const std::string mode1_with_follows =
    paper +
    " --branch mode1 --shooting_elements 40 --period 3.1 --ds 0.05 --ds_max 0.05 "
    "--max_points 60 --detect_branch_points true --follow all";

// The verified row whose period is nearest `period`; -1 when there is none.
int verified_row_near(const Table& t, double period) {
  const auto periods = t.column("period"), verified = t.column("verified");
  int best = -1;
  for (std::size_t i = 0; i < periods.size(); ++i)
    if (verified[i] == 1 &&
        (best < 0 || std::abs(periods[i] - period) <
                         std::abs(periods[static_cast<std::size_t>(best)] - period)))
      best = static_cast<int>(i);
  return best;
}

TEST(BranchPointsCli, BadFollowExitsTwoAndWritesNothing) {
  for (const char* bad : {"0", "-2", "some", "1.5"})
    cli::expect_bad_input("trace", paper + " --branch mode1 --follow " + bad, "follow",
                          "branch_points_cli");
  cli::expect_bad_input("trace", paper + " --branch mode1 --follow all --follow_max_points 0",
                        "follow_max_points", "branch_points_cli");
}

// The exact branch point: mode 1 of the paper scene (E = rho = L = A = 1, g0 = 1e-3) has
// u0 = eps x and T = 3 + g0 / |eps| (problems/contact_bar/orbits/README.md, 'Mode 1'); at T = 3.2,
// |eps| = 5e-3, E = eps^2 / 2 = 1.25e-5 and end amplitude 5e-3. Location: 1e-6 relative, the
// acceptance for a point found at two resolutions.
TEST(BranchPointsCli, DetectsTheModeOnePointAtTheExactPeriod) {
  const fs::path out = cli::scratch("branch_points_cli", "detect");
  const cli::Run r = cli::run("trace", detecting, out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table t = Table::read_csv(out / "branch_points.csv");
  for (const char* column : {"period", "frequency", "energy", "dimension", "frequency_ratio",
                             "tangent_angle", "verified"})
    EXPECT_NE(std::find(t.columns().begin(), t.columns().end(), column), t.columns().end())
        << column;
  const int row = verified_row_near(t, 3.2);
  ASSERT_GE(row, 0);
  const auto at = [&](const char* column) {
    return t.column(column)[static_cast<std::size_t>(row)];
  };
  EXPECT_NEAR(at("period") / 3.2, 1.0, 1e-6);
  EXPECT_NEAR(at("frequency") * 3.2 / (2 * M_PI), 1.0, 1e-6);
  // The located point is corrected on a hyperplane orthogonal to mode 1, which holds the attached
  // directions: it may sit slightly on the attached family, whose energy grows at constant T and
  // amplitude, hence 1e-5 in energy and 1e-6 in amplitude.
  EXPECT_NEAR(at("energy") / 1.25e-5, 1.0, 1e-5);
  EXPECT_NEAR(at("end_amplitude") / 5e-3, 1.0, 1e-6);
  EXPECT_GE(at("dimension"), 1);
  // The attached content is high-frequency: its dominant harmonic is well above the orbit's.
  EXPECT_GT(at("frequency_ratio"), 2);
  // The attached family leaves transversally to mode 1. The angle is the smallest over the
  // probes of a 7-8 dimensional null space that re-correct, and which do, and where, follows the
  // round-off of the march (problems/contact_bar/solver/README.md, 'Hard cases'), so the angle
  // moves by degrees under equivalent formulas. Bound 60 (mode 1 itself would give 0).
  EXPECT_GT(at("tangent_angle"), 60);
  // summary.txt says what was found: the rows of branch_points.csv and the verified among them;
  // no stability counts where the run computed no multipliers.
  const auto summary = [&](const char* key) {
    return backbone::core::read_text_value(out / "summary.txt", key);
  };
  const auto verified = t.column("verified");
  EXPECT_EQ(summary("branch_points_located"), std::to_string(t.rows()));
  EXPECT_EQ(summary("branch_points_verified"),
            std::to_string(std::count(verified.begin(), verified.end(), 1.0)));
  EXPECT_EQ(summary("stable_points"), "-");
  fs::remove_all(out);
}

// --follow K names a row of branch_points.csv; an unverified row is not followed: its folder
// holds only summary.txt, which says so (row 1 at 40 intervals: the unverified dip at T = 3.33),
// and the run exits with the numerical-failure code (the branch asked for was not traced).
TEST(BranchPointsCli, UnverifiedRowIsNotFollowed) {
  const fs::path out = cli::scratch("branch_points_cli", "unverified");
  const cli::Run r = cli::run("trace", detecting + " --follow 1", out);
  EXPECT_EQ(r.code, backbone::core::exit_numerical_failure);
  EXPECT_NE(r.err.find("a followed branch"), std::string::npos) << r.err;
  const Table t = Table::read_csv(out / "branch_points.csv");
  ASSERT_GE(t.rows(), 1u);
  ASSERT_EQ(t.column("verified")[0], 0);
  EXPECT_TRUE(fs::exists(out / "branch_point_1" / "summary.txt"));
  EXPECT_FALSE(fs::exists(out / "branch_point_1" / "branch.csv"));
  EXPECT_FALSE(fs::exists(out / "branch_point_2"));  // --follow 1 follows row 1 only
  fs::remove_all(out);
}

// The family attached at T = 3.5 L/c at the paper's 100 intervals has 22-24 dimensions: the
// bordered Jacobian there has 21-23 singular values at the finite-difference noise, which
// Newton's default rank cut-off (1e-12) would divide the minimum-norm steps by, turning every
// step by 90 degrees. The follow corrector cuts at the rank threshold instead
// (follow_newton_options), so the followed branch takes its whole budget at constant period.
TEST(BranchPointsCli, FollowsTheManyDimensionalFamilyAtThreeAndAHalf) {
  const fs::path out = cli::scratch("branch_points_cli", "follow_3.5");
  const cli::Run r = cli::run("trace",
                              paper +
                                  " --branch mode1 --shooting_elements 100 --energy_max 3e-6 "
                                  "--detect_branch_points true --follow 3 --follow_max_points 10",
                              out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table t = Table::read_csv(out / "branch_points.csv");
  const int row = verified_row_near(t, 3.5);
  ASSERT_EQ(row, 2) << "row 3 (followed): T = 3.5 after a dip near 3.67 and T = 3.6";
  // 1e-7: in this trace (gap units) T = 3.5 shows as a dip, located by the V-fit of |tau| to
  // |tau| ~ 1e-8, where the test function's finite-difference noise stops it. Changes of the
  // Jacobian's rounding only (its pattern, its factorisation) move the located period by up to
  // about 1e-7; a wrong point is 1e-3 away.
  EXPECT_NEAR(t.column("period")[static_cast<std::size_t>(row)], 3.5, 1e-7);
  // Its 24 probes step across a kink of F (the period's column of J changes by rank one). They
  // learn it from the first probe's Jacobian and difference it at the others' starts
  // (continuation/branch_points/verify.cpp), so location and verification need far fewer
  // Jacobians than the probes, each of which would otherwise take at least one of its own
  // (measured: 16, the location's refinement on both sides of the root included).
  EXPECT_LE(t.column("jacobian_evaluations")[static_cast<std::size_t>(row)], 20);
  EXPECT_GE(t.column("dimension")[static_cast<std::size_t>(row)], 20);
  const fs::path dir = out / ("branch_point_" + std::to_string(row + 1));
  const Table b = Table::read_csv(dir / "branch.csv");
  EXPECT_EQ(b.rows(), 10u) << "ended early: " << r.err;
  for (double p : b.column("period")) EXPECT_NEAR(p / 3.5, 1.0, 1e-9);
  const Table check = Table::read_csv(dir / "closed_form_check.csv");
  for (const char* column : {"return_error_u", "return_error_v"})
    for (double e : check.column(column)) EXPECT_LE(e, 1e-6) << column;
}

// The candidates are located and verified on a second thread (the worker has its own copy of
// the problem, core::Problem::clone, and the loop's units of the moment each candidate was
// bracketed): every row must be the same bits as the loop's own thread gives
// (--locate_in_background false), the cost columns included but for the wall time, and so must
// the branch. A worker that saw other units, another Jacobian or the loop's counters would move
// the located periods and the counts.
TEST(BranchPointsCli, SecondThreadGivesTheRowsOfTheLoopsOwnBitForBit) {
  const std::string scene =
      paper +
      " --branch mode1 --shooting_elements 100 --energy_max 1e-2 --detect_branch_points true";
  const fs::path worker = cli::scratch("branch_points_cli", "worker");
  const fs::path inline_ = cli::scratch("branch_points_cli", "inline");
  // The worker's run keeps its stdout: each candidate gets a line as it is located.
  const std::string log = worker.string() + ".log";
  ASSERT_EQ(std::system((std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace " + scene +
                         " --out '" + worker.string() + "' > '" + log + "' 2>&1")
                            .c_str()),
            0);
  ASSERT_EQ(cli::run("trace", scene + " --locate_in_background false", inline_).code, 0);
  {
    std::ifstream in(log);
    int lines = 0, verified_lines = 0;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("  branch point after point ", 0) != 0) continue;
      ++lines;
      if (line.find(" verified, attached dimension ") != std::string::npos) ++verified_lines;
    }
    const Table t = Table::read_csv(worker / "branch_points.csv");
    const auto verified = t.column("verified");
    EXPECT_EQ(lines, static_cast<int>(t.rows()));
    EXPECT_EQ(verified_lines, std::count(verified.begin(), verified.end(), 1.0));
    fs::remove(log);
  }
  for (const char* file : {"branch_points.csv", "branch.csv"}) {
    const Table a = Table::read_csv(worker / file), b = Table::read_csv(inline_ / file);
    ASSERT_EQ(a.columns(), b.columns()) << file;
    ASSERT_EQ(a.rows(), b.rows()) << file;
    for (const std::string& column : a.columns()) {
      if (column == "seconds") continue;
      const auto x = a.column(column), y = b.column(column);
      for (std::size_t i = 0; i < x.size(); ++i)  // NaN (an unverified row's ratio) matches NaN
        EXPECT_TRUE(x[i] == y[i] || (std::isnan(x[i]) && std::isnan(y[i])))
            << file << " " << column << " row " << i << ": " << x[i] << " vs " << y[i];
    }
  }
  EXPECT_EQ(Table::read_csv(worker / "branch_points.csv").rows(), 6u);
  fs::remove_all(worker);
  fs::remove_all(inline_);
}

// A resumed detecting trace re-adds its saved point, which locates again what adding that point
// had located: the interrupted run's rows from there on are replaced, not repeated. At 100
// intervals mode 1 meets six candidates (after points 5, 7, 8, 11, 17, 20). Cut at 9 points the
// saved point 8 brackets T = 3.5 with point 7, whose row must not be written twice; cut at 21 the
// re-located row is the unverified 3.142, whose table lacks the description columns
// (frequency_ratio, ...), and the merge must keep the interrupted run's rows. Periods agree with
// the uninterrupted run's to the test function's noise (the resumed sample is recomputed in that
// point's units, continuation/README.md 'Branch points'), well inside 1e-6 relative.
TEST(BranchPointsCli, ResumedRunNeitherRepeatsNorDropsCandidates) {
  const std::string scene =
      paper +
      " --branch mode1 --shooting_elements 100 --energy_max 1e-2 --detect_branch_points true";
  const fs::path full = cli::scratch("branch_points_cli", "full");
  ASSERT_EQ(cli::run("trace", scene, full).code, 0);
  const Table a = Table::read_csv(full / "branch_points.csv");
  ASSERT_EQ(a.rows(), 6u);
  for (int cut : {9, 21}) {
    const fs::path part = cli::scratch("branch_points_cli", "part_" + std::to_string(cut));
    ASSERT_EQ(cli::run("trace", scene + " --max_points " + std::to_string(cut), part).code, 0);
    const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                               part.string() + "' --max_points 1000 > /dev/null 2>&1";
    ASSERT_EQ(std::system(resume.c_str()), 0) << cut;
    const Table b = Table::read_csv(part / "branch_points.csv");
    ASSERT_EQ(b.rows(), a.rows()) << "cut at " << cut;
    EXPECT_EQ(b.column("after_point"), a.column("after_point")) << cut;
    EXPECT_EQ(b.column("verified"), a.column("verified")) << cut;
    EXPECT_EQ(b.columns(), a.columns()) << cut;
    for (std::size_t i = 0; i < a.rows(); ++i) {
      if (a.column("verified")[i] == 1) {
        EXPECT_NEAR(b.column("period")[i] / a.column("period")[i], 1.0, 1e-6) << cut << " " << i;
      }
    }
  }
}

// What SIGKILL leaves when location runs behind the loop (branch_points.hpp): branch.csv holds
// points whose brackets were still being located, branch_points.txt the candidates located so
// far and how many brackets had settled, and no branch_points.csv (written when the branch
// ends). Made exactly here: a run cut at 21 points, its branch_points.csv removed and its saved
// list cut back to the first three brackets. The resume must take up the last point whose
// state had made no more than three brackets (the points after it are traced again, bit for
// bit: unknowns.csv equals the uninterrupted run's byte for byte), keep the three saved
// candidates, locate the others again, and follow every verified one: the same rows, after the
// same points, verified alike, with a branch_point_K/ for each verified K.
TEST(BranchPointsCli, KilledRunLosesNoCandidateAndFollowsThemAll) {
  const std::string scene = paper +
                            " --branch mode1 --shooting_elements 100 --energy_max 1e-2 "
                            "--detect_branch_points true --follow all --follow_max_points 3";
  const fs::path full = cli::scratch("branch_points_cli", "full"),
                 part = cli::scratch("branch_points_cli", "killed");
  ASSERT_EQ(cli::run("trace", scene, full).code, 0);
  ASSERT_EQ(cli::run("trace", scene + " --max_points 21", part).code, 0);
  fs::remove(part / "branch_points.csv");
  std::ifstream in(part / "branch_points.txt");
  std::string text, line;
  int kept = 0;
  for (int n = 0; std::getline(in, line); ++n) {
    if (n == 1) line = "settled=3";
    if (n >= 2 && std::stoi(line.substr(line.find("bracket=") + 8)) >= 3) continue;
    kept += n >= 2;
    text += line + "\n";
  }
  in.close();
  ASSERT_EQ(kept, 3);  // every bracket gives one candidate, verified or not
  std::ofstream(part / "branch_points.txt") << text;
  const std::string log = part.string() + ".log";
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             part.string() + "' --max_points 1000 > '" + log + "' 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0) << cli::file_text(log);
  EXPECT_NE(cli::file_text(log).find("to 20 are traced again"), std::string::npos)
      << cli::file_text(log);
  EXPECT_EQ(cli::file_text(part / "unknowns.csv"), cli::file_text(full / "unknowns.csv"));
  const Table a = Table::read_csv(full / "branch_points.csv");
  const Table b = Table::read_csv(part / "branch_points.csv");
  ASSERT_GE(a.rows(), 6u);
  ASSERT_EQ(b.rows(), a.rows());
  EXPECT_EQ(b.column("after_point"), a.column("after_point"));
  EXPECT_EQ(b.column("verified"), a.column("verified"));
  EXPECT_EQ(cli::file_text(part / "branch_points.csv"), cli::file_text(full / "branch_points.csv"));
  for (std::size_t k = 1; k <= a.rows(); ++k) {
    const fs::path dir = "branch_point_" + std::to_string(k);
    EXPECT_EQ(fs::exists(part / dir / "branch.csv"), fs::exists(full / dir / "branch.csv")) << k;
    if (a.column("verified")[k - 1] == 1) {
      EXPECT_TRUE(fs::exists(part / dir / "branch.csv")) << k;
    }
  }
}

// A run killed after its loop reached max_points, during its follows: summary.txt still says
// "running", branch_points.csv and the followed folders are not written yet. The kill is made
// exactly: the uninterrupted run's folder with those files removed and the status set back. The
// resume has no point left to trace; it writes branch_points.csv and follows every verified
// candidate again, byte for byte the uninterrupted run's. A finished run at its max_points is
// still refused: resuming it would trace nothing.
TEST(BranchPointsCli, RunKilledDuringItsFollowsResumesTheFollows) {
  const std::string scene = mode1_with_follows + " --follow_max_points 5";
  const fs::path full = cli::scratch("branch_points_cli", "full"),
                 part = cli::scratch("branch_points_cli", "killed");
  ASSERT_EQ(cli::run("trace", scene, full).code, 0);
  const Table a = Table::read_csv(full / "branch_points.csv");
  ASSERT_GE(a.rows(), 2u);
  fs::copy(full, part, fs::copy_options::recursive);
  const std::string log = part.string() + ".log";
  const auto resume = [&] {
    const std::string command = std::string(BACKBONE_BINARY_DIR) +
                                "/bin/backbone trace --resume '" + part.string() + "' > '" + log +
                                "' 2>&1";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(resume(), 2) << cli::file_text(log);
  EXPECT_NE(cli::file_text(log).find("max_points: the saved branch has 60 points"),
            std::string::npos)
      << cli::file_text(log);
  fs::remove(part / "branch_points.csv");
  for (std::size_t k = 1; k <= a.rows(); ++k)
    fs::remove_all(part / ("branch_point_" + std::to_string(k)));
  std::string summary = cli::file_text(part / "summary.txt");
  const auto status = summary.find("status complete");
  ASSERT_NE(status, std::string::npos) << summary;
  summary.replace(status, 15, "status running");
  std::ofstream(part / "summary.txt") << summary;

  ASSERT_EQ(resume(), 0) << cli::file_text(log);
  for (const char* file :
       {"branch.csv", "unknowns.csv", "state.txt", "branch_points.csv", "summary.txt"})
    EXPECT_EQ(cli::file_text(part / file), cli::file_text(full / file)) << file;
  int followed = 0;
  for (std::size_t k = 1; k <= a.rows(); ++k) {
    const fs::path dir = "branch_point_" + std::to_string(k);
    EXPECT_EQ(fs::exists(part / dir), fs::exists(full / dir)) << k;
    if (!fs::exists(full / dir / "unknowns.csv")) continue;
    ++followed;
    EXPECT_EQ(cli::file_text(part / dir / "unknowns.csv"),
              cli::file_text(full / dir / "unknowns.csv"))
        << k;
  }
  EXPECT_GE(followed, 2);
}

// SIGINT while the run follows its branch points (sent when branch_point_1/ appears): the
// follow under way stops at its next point, the rows after it are left, the run exits 130 with
// summary.txt's status "interrupted", and --resume does the follows again: the same files as the
// uninterrupted run, byte for byte.
TEST(BranchPointsCli, InterruptDuringTheFollowsIsResumed) {
  const std::string scene = mode1_with_follows + " --follow_max_points 200";
  const fs::path full = cli::scratch("branch_points_cli", "full"),
                 part = cli::scratch("branch_points_cli", "interrupted");
  ASSERT_EQ(cli::run("trace", scene, full).code, 0);
  const std::string log = part.string() + ".log";
  const std::string command = "exec " + std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace " +
                              scene + " --out '" + part.string() + "' > '" + log + "' 2>&1";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    setpgid(0, 0);  // backbone (exec'd by the shell) in a group of its own, as from a terminal
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  setpgid(pid, pid);
  int status = 0;
  bool signalled = false;
  for (int waited = 0; waited < 600000 && waitpid(pid, &status, WNOHANG) == 0; ++waited) {
    if (!signalled && fs::exists(part / "branch_point_1")) {
      kill(-pid, SIGINT);
      signalled = true;
    }
    usleep(100);
  }
  ASSERT_TRUE(signalled) << cli::file_text(log);
  ASSERT_TRUE(WIFEXITED(status)) << cli::file_text(log);
  EXPECT_EQ(WEXITSTATUS(status), 130) << cli::file_text(log);
  EXPECT_EQ(backbone::core::read_text_value(part / "summary.txt", "status"), "interrupted");
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             part.string() + "' > '" + log + "' 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0) << cli::file_text(log);
  for (const char* file : {"branch.csv", "unknowns.csv", "branch_points.csv", "summary.txt"})
    EXPECT_EQ(cli::file_text(part / file), cli::file_text(full / file)) << file;
  const Table a = Table::read_csv(full / "branch_points.csv");
  for (std::size_t k = 1; k <= a.rows(); ++k) {
    const fs::path dir = "branch_point_" + std::to_string(k);
    EXPECT_EQ(cli::file_text(part / dir / "unknowns.csv"),
              cli::file_text(full / dir / "unknowns.csv"))
        << k;
  }
}

}  // namespace

// --follow all: the family attached at T = 3.2 is traced into branch_point_K/ (K: its row). It
// leaves mode 1 at constant frequency, as an internal resonance does: every point keeps T = 3.2
// within 1e-9 relative (the period is not pinned, it is the family's), its energy grows from the
// branch point's, and every orbit returns under the exact oracle within return_tolerance = 1e-6
// (trace's per-point check; closed_form_check.csv checks it again on another grid).
TEST(BranchPointsCli, FollowsTheAttachedFamilyAtConstantPeriod) {
  const fs::path root = cli::scratch("branch_points_cli", "follow"),
                 out = root / "mode1_resonances";
  fs::create_directories(root);
  const cli::Run r = cli::run("trace", detecting + " --follow all --follow_max_points 30", out);
  ASSERT_EQ(r.code, 0) << r.err;
  const Table t = Table::read_csv(out / "branch_points.csv");
  const int row = verified_row_near(t, 3.2);
  ASSERT_GE(row, 0);
  const fs::path dir = out / ("branch_point_" + std::to_string(row + 1));
  for (const char* file : {"branch.csv", "orbits.csv", "unknowns.csv", "summary.txt"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  // Without multipliers its summary counts none.
  EXPECT_EQ(backbone::core::read_text_value(dir / "summary.txt", "stable_points"), "-");
  // The followed family is corrected with the trace's Jacobian (the scene's default, exact).
  EXPECT_EQ(backbone::core::read_text_value(dir / "summary.txt", "jacobian"), "exact");
  const Table b = Table::read_csv(dir / "branch.csv");
  ASSERT_GE(b.rows(), 5u);
  const auto period = b.column("period"), energy = b.column("energy");
  for (double p : period) EXPECT_NEAR(p / 3.2, 1.0, 1e-9);
  EXPECT_GT(energy.front(), 1.25e-5);
  // The path inside the 5-7 dimensional family follows the round-off of the march and of the
  // Jacobian (see tangent_angle), and so does how far its energy climbs in 30 points: by a
  // quarter with differences, 1.24 with the exact Jacobian, or to the bound 3e-5. A tenth says
  // the follow left the branch point.
  EXPECT_GT(energy.back(), 1.1 * 1.25e-5);
  const Table check = Table::read_csv(dir / "closed_form_check.csv");
  for (const char* column : {"return_error_u", "return_error_v"})
    for (double e : check.column(column)) EXPECT_LE(e, 1e-6) << column;
  // Unverified rows are not followed.
  const auto verified = t.column("verified");
  for (std::size_t i = 0; i < verified.size(); ++i)
    if (verified[i] == 0) {
      EXPECT_FALSE(fs::exists(out / ("branch_point_" + std::to_string(i + 1))));
    }

  // The figures of the followed branch (problems/contact_bar/figures/resonance.hpp). Fig. 11's
  // mode-1 orbit at the attached orbit's period is the closed form: u(L, 0) = eps L = -5e-3 (T
  // = 3.2 to 1e-9, so 1e-8 relative) and contact at u(L) = g0 = 1e-3 (the exact oracle: round-off).
  // The attached orbit is mode 1 plus low-magnitude content: differs by more than 1e-6 and less
  // than g0. From the source folder: the figure jobs read the paper scene by its repository path.
  // The followed run is in mode1_resonances (the main job's folder); it also stands for mode1, so
  // that the backbone figure has its branch.
  fs::remove_all(root / "mode1");
  fs::create_directory_symlink("mode1_resonances", root / "mode1");
  const std::string figures = "cd '" + std::string(BACKBONE_SOURCE_DIR) + "' && '" +
                              std::string(BACKBONE_BINARY_DIR) + "/bin/backbone' figures --out '" +
                              root.string() + "' > /dev/null 2>&1";
  ASSERT_EQ(std::system(figures.c_str()), 0);
  const std::string k = std::to_string(row + 1);
  const Table mode1 = Table::read_csv(root / ("resonant_end_" + k + "_mode1.csv"));
  const Table resonant = Table::read_csv(root / ("resonant_end_" + k + "_attached.csv"));
  const auto u1 = mode1.column("u_contact"), ur = resonant.column("u_contact");
  ASSERT_EQ(u1.size(), ur.size());
  EXPECT_NEAR(u1.front() / -5e-3, 1.0, 1e-8);
  EXPECT_NEAR(*std::max_element(u1.begin(), u1.end()), 1e-3, 1e-12);
  double content = 0;
  for (std::size_t i = 0; i < u1.size(); ++i) content = std::max(content, std::abs(ur[i] - u1[i]));
  EXPECT_GT(content, 1e-6);
  EXPECT_LT(content, 1e-3);
  EXPECT_TRUE(fs::exists(root / "resonant_spacetime.csv"));
  fs::remove_all(root);
}
