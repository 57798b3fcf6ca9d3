// `backbone trace` end to end on the contact bar: bad input names its key (exit 2, nothing
// written); another scene than the paper's (other L, E, rho, g0 on the command line, nothing
// else changed) traces mode 1 onto the closed form of problems/contact_bar/orbits/README.md, 'Mode
// 1', because the continuation works in units of the scene (u0 / g0, T c / L) and checks each
// point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/io/scene_ini.hpp"
#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

namespace fs = std::filesystem;

const std::string paper =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";

std::string fmt_points(std::size_t rows) {
  return "points " + std::to_string(rows) + "\n";
}

void expect_bad_input(const std::string& arguments, const std::string& key) {
  cli::expect_bad_input("trace", arguments, key, "trace_cli");
}

// Traces mode 1 of the paper scene with extra arguments into a scratch folder named `name`;
// every point must match the closed form at its own energy: acceptance 1e-5, asserted 1e-8, far
// above what the Newton tolerance 1e-10 g0 leaves. Returns closed_form_check.csv.
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

// The subharmonic backbone lies in a continuum of two dimensions (energy and shape; the closed
// form of problems/contact_bar/orbits/README.md, 'Subharmonic continuum'), which the verified
// rank report of F alone must find at every point with either Jacobian. The exact one's two
// null singular values sit at round-off, so the probes' corrector must cut them like the report
// does (core::make_verifier): with a cut-off of 1e-12 its probes drifted off at 11 of these points
// (energies 2.3e-4 to 1.1e-3 J) and the dimension read 1 there.
TEST(TraceCli, TheSubharmonicContinuumIsTwoDimensionalWithEitherJacobian) {
  for (const std::string jacobian : {"differences", "exact"}) {
    const fs::path out = cli::scratch("trace_cli", "subharmonic_" + jacobian);
    const cli::Run r = cli::run(
        "trace", paper + " --branch subharmonic --energy_max 1.2e-3 --jacobian " + jacobian, out);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto dimensions =
        backbone::core::Table::read_csv(out / "subharmonic_check.csv").column("dimension_F");
    EXPECT_GE(dimensions.size(), 20u);
    for (std::size_t i = 0; i < dimensions.size(); ++i)
      EXPECT_EQ(dimensions[i], 2) << jacobian << " point " << i;
    // The traced curve has path rows: its corrections take differences whatever was asked,
    // while the rank reports of F alone take the asked one; summary.txt says so (scene.ini keeps
    // the key as given).
    EXPECT_EQ(backbone::core::read_text_value(out / "summary.txt", "jacobian"),
              jacobian == "exact"
                  ? "differences for the curve (path rows); exact for F alone (rank reports, atlas)"
                  : "differences");
    fs::remove_all(out);
  }
}

TEST(TraceCli, BadInputExitsTwoAndWritesNothing) {
  expect_bad_input(paper + " --branch mode3x", "branch");
  expect_bad_input(paper + " --ds 0", "ds");
  expect_bad_input(paper + " --test_elements 5", "test_elements");
  expect_bad_input(paper + " --steps_per_period 41", "steps_per_period");
  expect_bad_input(paper + " --return_tolerance -1", "return_tolerance");
  expect_bad_input(paper + " --right_end free", "right_end");
  expect_bad_input(paper + " --predictor cubic", "predictor");
  expect_bad_input(paper + " --newton_jacobian_check 1", "newton_jacobian_check");
  // The size of a residual is bounded before any work: 1e7 steps per period at 20 intervals, a
  // million intervals at 40 steps, both above max_residual_work 1e7.
  expect_bad_input(paper + " --steps_per_period 10000000", "steps_per_period");
  expect_bad_input(paper + " --shooting_elements 1000000", "shooting_elements");
  expect_bad_input(paper + " --branch subharmonic --steps_per_period 10000000", "steps_per_period");
  // KINSOL is square-only; the default residual is oversampled (test_elements = -1).
  expect_bad_input(paper + " --newton kinsol", "newton");
}

// A short soft bar (L = 0.3 m, E = 7e4 Pa, rho = 2.7 kg/m^3: c = 161 m/s) with a 10 um gap:
// u0 ~ 1e-5 m, T ~ 3 L/c = 5.6e-3 s. u0, period and dt are given for this bar (the scene's are
// for L = 1 and are refused); the default dimensionless steps fit. Every point must match the
// closed form at its own energy and return under the exact oracle (the per-point check of
// trace, 1e-6).
TEST(TraceCli, OtherSceneModeOneMatchesTheClosedForm) {
  fs::path out;
  const auto check = trace_mode1_on_the_closed_form(
      "short_bar",
      "--length 0.3 --youngs_modulus 7e4 --density 2.7 --gap 1e-5 --energy_max 1e-3 "
      "--u0 '0:0 0.3:-3e-5' --period 0.0055 --dt 1e-5",
      out);
  const auto energy = check.column("energy");
  ASSERT_FALSE(energy.empty());
  EXPECT_NEAR(energy.back(), 1e-3, 1e-9);  // landed on the bound
  // Grazing energy EA g0^2 / (2L) = 7e4 * 1e-10 / 0.6; the start is 5 % above in amplitude.
  EXPECT_NEAR(energy.front(), 1.05 * 1.05 * 7e4 * 1e-10 / 0.6, 1e-15);
  fs::remove_all(out);
}

// Natural continuation in the period, the paper's parameter, on the oversampled (rectangular)
// residual: T falls from 3.95 towards 3 L/c, each point on the closed form (1e-8, as above).
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

// Columns of two branch.csv files that must agree bit for bit: all but the cost of a point
// (seconds, evaluation counts: a resumed run's first Jacobian is not the cached one).
void expect_same_rows(const backbone::core::Table& a, const backbone::core::Table& b,
                      std::size_t a_first, std::size_t b_first) {
  ASSERT_EQ(a.columns(), b.columns());
  ASSERT_EQ(a.rows() - a_first, b.rows() - b_first);
  for (std::size_t j = 0; j < a.columns().size(); ++j) {
    const std::string& c = a.columns()[j];
    if (c == "seconds" || c == "jacobian_evaluations" || c == "residual_evaluations") continue;
    const auto x = a.column(c), y = b.column(c);
    for (std::size_t i = 0; i + b_first < y.size(); ++i)
      EXPECT_TRUE(x[a_first + i] == y[b_first + i] ||
                  (std::isnan(x[a_first + i]) && std::isnan(y[b_first + i])))
          << c << " at row " << a_first + i << ": " << x[a_first + i] << " vs " << y[b_first + i];
  }
}

using cli::file_text;

// mode 1 on a coarse grid up to 2e-3 J: 88 cheap points (steps of 5 % of the amplitude above
// the gap: amplitude_units, problems/contact_bar/orbits/README.md 'Amplitude units').
const std::string small_mode1 =
    paper + " --branch mode1 --shooting_elements 10 --energy_max 2e-3 --ds 0.05 --ds_max 0.05";

// An interrupted trace keeps its points and --resume continues it from the loop state saved
// with its last complete point (state.txt, continuation/restart.hpp): a 30-point run whose last
// unknowns.csv row is cut (what SIGKILL mid-write leaves) is repaired to 29 complete points and
// resumed without a point budget to the energy bound. The whole branch, to its end, is the
// uninterrupted run's bit for bit (the restart corrects and re-derives nothing), and so are
// unknowns.csv and state.txt byte for byte, and the closed-form check and branch points cover the
// whole branch.
TEST(TraceCli, ResumeContinuesAnInterruptedBranch) {
  const fs::path full = cli::scratch("trace_cli", "full"), part = cli::scratch("trace_cli", "part");
  // In fixed units: with amplitude_units the resumed point's detector sample is recomputed from a
  // Jacobian in that point's units (the first run's was in the previous point's), equal to the
  // finite differences' noise, not bit for bit (continuation/README.md, 'Branch points').
  const std::string detect = small_mode1 + " --detect_branch_points true --amplitude_units false";
  ASSERT_EQ(cli::run("trace", detect, full).code, 0);
  ASSERT_EQ(cli::run("trace", detect + " --max_points 30", part).code, 0);
  const fs::path unknowns = part / "unknowns.csv";
  fs::resize_file(unknowns, fs::file_size(unknowns) - 10);  // cut the last row
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             part.string() + "' --max_points 1000 > '" + part.string() +
                             ".log' 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0);
  EXPECT_NE(file_text(part.string() + ".log")
                .find("restarting from point 28 (its saved loop "
                      "state)"),
            std::string::npos)
      << file_text(part.string() + ".log");
  const auto a = backbone::core::Table::read_csv(full / "branch.csv");
  const auto b = backbone::core::Table::read_csv(part / "branch.csv");
  EXPECT_GE(a.rows(), 60u);  // the resumed part is most of the branch
  expect_same_rows(a, b, 0, 0);
  EXPECT_EQ(file_text(part / "unknowns.csv"), file_text(full / "unknowns.csv"));
  EXPECT_EQ(file_text(part / "state.txt"), file_text(full / "state.txt"));
  // The outputs written after the run cover the whole branch, saved points included.
  EXPECT_EQ(file_text(part / "closed_form_check.csv"), file_text(full / "closed_form_check.csv"));
  const auto bp_full = backbone::core::Table::read_csv(full / "branch_points.csv");
  const auto bp_part = backbone::core::Table::read_csv(part / "branch_points.csv");
  EXPECT_GE(bp_full.rows(), 1u);  // else the comparison below says nothing
  ASSERT_EQ(bp_part.rows(), bp_full.rows());
  for (const char* c : {"period", "energy", "after_point"})
    EXPECT_EQ(bp_part.column(c), bp_full.column(c)) << c;
  EXPECT_NE(file_text(part / "summary.txt").find(fmt_points(a.rows())), std::string::npos);
  fs::remove_all(full);
  fs::remove_all(part);
  fs::remove(part.string() + ".log");
}

// A resume from the point before the landing on the energy bound lands as the uninterrupted run
// did: the loop aims its step at the bound along the chord of its last two points, which a
// resumed loop takes from the files (LoopState::known_points). Without them it crossed the bound
// and landed back, on other bits. branch.csv and unknowns.csv byte for byte.
TEST(TraceCli, ResumeBeforeTheLandingLandsBitForBit) {
  const fs::path full = cli::scratch("trace_cli", "full"), part = cli::scratch("trace_cli", "part");
  ASSERT_EQ(cli::run("trace", small_mode1, full).code, 0);
  const std::size_t rows = backbone::core::Table::read_csv(full / "branch.csv").rows();
  ASSERT_GE(rows, 3u);
  EXPECT_EQ(backbone::core::read_text_value(full / "summary.txt", "stop_reason"), "bound_reached");
  ASSERT_EQ(cli::run("trace", small_mode1 + " --max_points " + std::to_string(rows - 1), part).code,
            0);
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             part.string() + "' --max_points 1000 > '" + part.string() +
                             ".log' 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0) << file_text(part.string() + ".log");
  EXPECT_EQ(file_text(part / "branch.csv"), file_text(full / "branch.csv"));
  EXPECT_EQ(file_text(part / "unknowns.csv"), file_text(full / "unknowns.csv"));
  fs::remove_all(full);
  fs::remove_all(part);
  fs::remove(part.string() + ".log");
}

// The impact oscillator's elastic branch up to its grazing (11 points, 3 refused corrections:
// one before point 10, two before its last step reaches the bound). Stopped at 11 points, its
// resume has no point to add: the next step ends the branch, as in the uninterrupted run. The
// resume is complete (exit 0), and its files, summary.txt included, are the uninterrupted run's:
// the refused corrections of the first run are counted from the saved loop state. A new branch
// started from the last point counts its own alone.
TEST(TraceCli, AResumeWhoseFirstStepEndsTheBranchCompletesIt) {
  const std::string scene = std::string(BACKBONE_SOURCE_DIR) +
                            "/problems/impact_oscillator/scenes/impact.ini --restitution 1";
  const fs::path full = cli::scratch("trace_cli", "impact_full"),
                 part = cli::scratch("trace_cli", "impact_part");
  ASSERT_EQ(cli::run("trace", scene, full).code, 0);
  const std::size_t rows = backbone::core::Table::read_csv(full / "branch.csv").rows();
  ASSERT_EQ(cli::run("trace", scene + " --max_points " + std::to_string(rows), part).code, 0);
  const auto refused = [](const fs::path& dir) {
    return std::stoi(backbone::core::read_text_value(dir / "summary.txt", "rejected_corrections"));
  };
  const int before_split = refused(part);
  ASSERT_GT(refused(full), before_split);  // some are refused after the split
  const fs::path started = cli::scratch("trace_cli", "impact_started");
  ASSERT_EQ(
      cli::run("trace", scene + " --start '" + part.string() + ":" + std::to_string(rows - 1) + "'",
               started)
          .code,
      0);
  EXPECT_EQ(refused(started), refused(full) - before_split);
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             part.string() + "' --max_points 1000 > '" + part.string() +
                             ".log' 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0) << file_text(part.string() + ".log");
  for (const char* f : {"branch.csv", "unknowns.csv", "summary.txt", "state.txt",
                        "bifurcations.csv", "multipliers.csv", "branch.png"})
    EXPECT_EQ(file_text(part / f), file_text(full / f)) << f;
  fs::remove_all(full);
  fs::remove_all(part);
  fs::remove_all(started);
  fs::remove(part.string() + ".log");
}

// A branch that ended on its bound gains no point when taken up again (the restart's last
// point lies on the bound: landing again would add a copy of it), whatever other key is given:
// branch.csv stays byte for byte, exit 0. A key that moves the bound extends it.
TEST(TraceCli, ResumingABranchOnItsBoundAddsNothingUnlessTheBoundMoves) {
  const fs::path done = cli::scratch("trace_cli", "done");
  ASSERT_EQ(cli::run("trace", small_mode1 + " --stability true", done).code, 0);
  // The outputs written after the run too: the restart point is the saved one, not the one
  // corrected again (its last point has no saved loop state).
  const std::vector<std::string> files = {"branch.csv", "closed_form_check.csv", "multipliers.csv",
                                          "fronts.csv"};
  std::vector<std::string> before;
  for (const std::string& f : files) {
    before.push_back(file_text(done / f));
    ASSERT_FALSE(before.back().empty()) << f;
  }
  const std::string resume =
      std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" + done.string() + "'";
  const std::string log = " > '" + done.string() + ".log' 2>&1";
  for (const std::string keys : {"", " --threads 2"}) {
    ASSERT_EQ(std::system((resume + keys + log).c_str()), 0) << file_text(done.string() + ".log");
    for (std::size_t i = 0; i < files.size(); ++i)
      EXPECT_EQ(file_text(done / files[i]), before[i]) << files[i] << keys;
  }
  ASSERT_EQ(std::system((resume + " --energy_max 3e-3" + log).c_str()), 0)
      << file_text(done.string() + ".log");
  const auto extended = backbone::core::Table::read_csv(done / "branch.csv");
  EXPECT_GT(extended.column("energy").back(), 2.5e-3);
  fs::remove_all(done);
  fs::remove(done.string() + ".log");
}

// A finished branch far above the gap is extended from its last point, which has no loop state
// (it lies on the bound) and is corrected again: in its own amplitude units, where its points
// converged; in gap units the residual's round-off of mode 1 at 200 intervals and E = 1e-2 is
// above the tolerance 1e-10. Every extended point keeps the closed form (mode 1: the trace's own
// check, closed_form_check.csv; 1e-8, as above).
TEST(TraceCli, FinishedBranchFarAboveTheGapExtends) {
  const fs::path done = cli::scratch("trace_cli", "extend");
  ASSERT_EQ(
      cli::run("trace", paper + " --branch mode1 --shooting_elements 200 --energy_max 1e-2", done)
          .code,
      0);
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             done.string() + "' --energy_max 2e-2 > '" + done.string() +
                             ".log' 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0) << file_text(done.string() + ".log");
  const auto t = backbone::core::Table::read_csv(done / "branch.csv");
  EXPECT_NEAR(t.column("energy").back(), 2e-2, 1e-12);
  const auto check = backbone::core::Table::read_csv(done / "closed_form_check.csv");
  for (double e : check.column("relative_error")) EXPECT_LE(e, 1e-8);
  fs::remove_all(done);
  fs::remove(done.string() + ".log");
}

// A resumed run reads the resolved scene.ini, where keys left at their defaults are comments: in
// the amplitude units (mode 1's default) newton_tolerance is then still "not given" and the
// branch keeps its own 1e-10 (problems/contact_bar/orbits/README.md, 'Amplitude units'), so the
// resumed branch is the uninterrupted one's point for point.
TEST(TraceCli, ResumeInTheAmplitudeUnitsKeepsTheBranchsOwnSettings) {
  const fs::path full = cli::scratch("trace_cli", "full_amp"),
                 part = cli::scratch("trace_cli", "part_amp");
  ASSERT_EQ(cli::run("trace", small_mode1, full).code, 0);
  ASSERT_EQ(cli::run("trace", small_mode1 + " --max_points 30", part).code, 0);
  EXPECT_NE(file_text(part / "scene.ini").find("# newton_tolerance = 3e-09  (default)"),
            std::string::npos)
      << file_text(part / "scene.ini");
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             part.string() + "' --max_points 1000 > '" + part.string() +
                             ".log' 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0) << file_text(part.string() + ".log");
  const auto a = backbone::core::Table::read_csv(full / "branch.csv");
  ASSERT_GE(a.rows(), 60u);  // the resumed part is most of the branch
  expect_same_rows(a, backbone::core::Table::read_csv(part / "branch.csv"), 0, 0);
  EXPECT_EQ(file_text(part / "unknowns.csv"), file_text(full / "unknowns.csv"));
  fs::remove_all(full);
  fs::remove_all(part);
  fs::remove(part.string() + ".log");
}

// --start DIR/orbits.csv:K takes up the loop state saved with point K: the new folder holds
// point K (recorded again: its Newton iterations and step are 0, it is the new branch's first
// point) and then exactly the saved branch's points K + 1, ... to its end, bit for bit.
// --direction -1 goes back from K towards grazing (the energy falls).
TEST(TraceCli, StartFromASavedPointReproducesTheRestOfTheBranch) {
  const fs::path full = cli::scratch("trace_cli", "full"), from = cli::scratch("trace_cli", "from"),
                 back = cli::scratch("trace_cli", "back");
  ASSERT_EQ(cli::run("trace", small_mode1, full).code, 0);
  const std::string start = " --start '" + (full / "orbits.csv").string() + ":40'";
  ASSERT_EQ(cli::run("trace", small_mode1 + start, from).code, 0);
  const auto a = backbone::core::Table::read_csv(full / "branch.csv");
  const auto b = backbone::core::Table::read_csv(from / "branch.csv");
  ASSERT_GT(a.rows(), 45u);
  EXPECT_EQ(b.column("point").front(), 40);
  // Point K itself is recorded from its saved state, kept in fixed units, while the first run
  // recorded it in the units of its amplitude (LocalScale): the conversions may differ in the
  // last bits (hence 1e-14). The points after it are the same bit for bit.
  EXPECT_NEAR(b.column("energy").front() / a.column("energy")[40], 1.0, 1e-14);
  expect_same_rows(a, b, 41, 1);
  ASSERT_EQ(cli::run("trace", small_mode1 + start + " --direction -1 --max_points 45", back).code,
            0);
  const auto energy = backbone::core::Table::read_csv(back / "branch.csv").column("energy");
  ASSERT_EQ(energy.size(), 5u);
  for (std::size_t i = 1; i < energy.size(); ++i) EXPECT_LT(energy[i], energy[i - 1]) << i;
  fs::remove_all(full);
  fs::remove_all(from);
  fs::remove_all(back);
}

// The paper's residual u0 - u(T) is degenerate on mode 1 (a double root: its period column
// vanishes, problems/contact_bar/README.md), so the null vector of its Jacobian at the first
// point is no tangent of the family. The first step follows the family's closed-form direction
// (start_along_direction); from there the secants carry the branch to its bound, every point on
// the closed form (1e-8, as above).
TEST(TraceCli, PaperFormulationDoesNotLeaveTheFamily) {
  const fs::path out = cli::scratch("trace_cli", "paper_formulation");
  const cli::Run r = cli::run("trace", paper + " --branch mode1 --formulation paper", out);
  EXPECT_EQ(r.code, 0) << r.err;
  const auto check = backbone::core::Table::read_csv(out / "closed_form_check.csv");
  const auto errors = check.column("relative_error");
  ASSERT_GE(errors.size(), 20u);
  for (double e : errors) EXPECT_LE(e, 1e-8);
  EXPECT_NEAR(check.column("energy").back(), 1e-2, 1e-12);  // energy_max of paper.ini
  fs::remove_all(out);
}

// A point of a traced curve has dimension >= 1. At end amplitudes that are whole multiples of
// g0 (T = 3 + 1/k: the contact events fall on the time grid) the candidate null space is several
// directions wide, and at 80 intervals and 10 g0 the verification's probes end near the
// residual's round-off. Every point must report dimension >= 1, and a point whose verification
// gives 0 is re-checked along the tangent and said on stderr and in summary.txt (dimension_flag,
// continuation/README.md).
TEST(TraceCli, DimensionOnTheCurveIsNeverZero) {
  const fs::path out = cli::scratch("trace_cli", "grid_coincidence");
  const cli::Run r = cli::run(
      "trace", paper + " --branch mode1 --shooting_elements 80 --start_offset 9 --max_points 2",
      out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto t = backbone::core::Table::read_csv(out / "branch.csv");
  const auto dimension = t.column("dimension"), flag = t.column("dimension_flag");
  const auto amplitude = t.column("end_amplitude");
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_NEAR(amplitude[0], 10 * 1e-3, 1e-15);  // exactly 10 g0, up to round-off
  EXPECT_GE(t.column("nullity")[0], 2);         // the coincidence is there
  long flagged = 0;
  for (std::size_t i = 0; i < t.rows(); ++i) {
    EXPECT_GE(dimension[i], 1) << "point " << i;
    EXPECT_NE(flag[i], 2) << "point " << i;
    flagged += flag[i] != 0;
  }
  // One line per flagged point (the dimension lines of points above the expected dimension,
  // 'verified dimension D where the branch expects 1', are counted apart).
  long flag_lines = 0;
  for (std::size_t at = r.err.find("contradicts"); at != std::string::npos;
       at = r.err.find("contradicts", at + 1))
    ++flag_lines;
  EXPECT_EQ(flag_lines, flagged) << r.err;
  EXPECT_NE(file_text(out / "summary.txt").find("dimension_rechecked " + std::to_string(flagged)),
            std::string::npos);
  fs::remove_all(out);
}

TEST(TraceCli, BackwardsFromASavedPointAsTheReadmeSays) {
  // README.md, 'Commands': backwards from point 50 of mode 1, bounded at 6e-7 J, exit 0; without
  // the bound the branch runs into mode 1's grazing limit (T = 4 L/c) and stops early, exit 1.
  const fs::path mode1 = cli::scratch("trace_cli", "readme_mode1");
  ASSERT_EQ(cli::run("trace", paper + " --branch mode1", mode1).code, 0);
  const std::string start =
      paper + " --branch mode1 --start " + (mode1 / "orbits.csv").string() + ":50 --direction -1";
  const fs::path bounded = cli::scratch("trace_cli", "readme_back");
  const cli::Run r = cli::run("trace", start + " --energy_min 6e-7", bounded);
  EXPECT_EQ(r.code, 0) << r.err;
  const auto energy = backbone::core::Table::read_csv(bounded / "branch.csv").column("energy");
  EXPECT_NEAR(energy.back(), 6e-7, 6e-7 * 1e-9);  // landed on the bound
  const fs::path unbounded = cli::scratch("trace_cli", "readme_back_to_grazing");
  const cli::Run g = cli::run("trace", start, unbounded);
  EXPECT_EQ(g.code, 1) << g.err;
  const auto period = backbone::core::Table::read_csv(unbounded / "branch.csv").column("period");
  EXPECT_NEAR(period.back(), 4.0, 1e-3);  // at the grazing limit, T = 4 L/c (L = c = 1)
  for (const fs::path& dir : {mode1, bounded, unbounded}) fs::remove_all(dir);
}

TEST(TraceCli, DimensionAboveTheExpectedIsSaidAndCounted) {
  // Far above the gap (end amplitude 1e8 g0, T - 3 = 1e-8 L/c) the attached families crowd mode
  // 1 and the verified dimension exceeds 1 (problems/contact_bar/orbits/README.md, 'Dimension
  // changes'): the run says so on stderr and summary.txt counts the points.
  const fs::path out = cli::scratch("trace_cli", "far_above_gap");
  const cli::Run r = cli::run("trace",
                              paper +
                                  " --branch mode1 --start_offset 1e8 --energy_max 1e30 "
                                  "--max_points 2",
                              out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto dimension = backbone::core::Table::read_csv(out / "branch.csv").column("dimension");
  const long above =
      std::count_if(dimension.begin(), dimension.end(), [](double d) { return d > 1; });
  ASSERT_GE(above, 1);
  EXPECT_NE(r.err.find("where the branch expects 1"), std::string::npos) << r.err;
  EXPECT_NE(
      file_text(out / "summary.txt").find("dimension_above_expected " + std::to_string(above)),
      std::string::npos);
  // Resumed for one more point, the count covers the whole branch.csv, its saved points too.
  const std::string resume = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume '" +
                             out.string() + "' --max_points 3 > /dev/null 2>&1";
  ASSERT_EQ(std::system(resume.c_str()), 0);
  const auto resumed = backbone::core::Table::read_csv(out / "branch.csv").column("dimension");
  ASSERT_EQ(resumed.size(), 3u);
  const long above_resumed =
      std::count_if(resumed.begin(), resumed.end(), [](double d) { return d > 1; });
  EXPECT_NE(file_text(out / "summary.txt")
                .find("dimension_above_expected " + std::to_string(above_resumed)),
            std::string::npos)
      << file_text(out / "summary.txt");
  fs::remove_all(out);
}

}  // namespace

namespace {

// The README's commands (README.md, 'Commands') that the main job does not run as written, run
// here as written, into a scratch folder in place of out/: each exits 0 and writes what the
// README says it writes.
TEST(ReadmeCommands, TraceResumeInspectContinuumAndAtlasRunAsWritten) {
  const fs::path root = cli::scratch("trace_cli", "readme_commands");
  fs::create_directories(root);
  const fs::path mode1 = root / "mode1";
  ASSERT_EQ(cli::run("trace", paper + " --branch mode1", mode1).code, 0);
  // A finished branch resumed: nothing left to do, exit 0, the same points.
  const auto before = backbone::core::Table::read_csv(mode1 / "branch.csv").rows();
  const std::string resume = std::string("'") + BACKBONE_BINARY_DIR +
                             "/bin/backbone' trace --resume '" + mode1.string() +
                             "' > /dev/null 2>&1";
  EXPECT_EQ(std::system(resume.c_str()), 0);
  EXPECT_EQ(backbone::core::Table::read_csv(mode1 / "branch.csv").rows(), before);
  const std::string inspect = std::string("'") + BACKBONE_BINARY_DIR + "/bin/backbone' inspect " +
                              paper + " --orbit '" + (mode1 / "orbits.csv").string() +
                              ":10' > /dev/null 2>&1";
  EXPECT_EQ(std::system(inspect.c_str()), 0);
  const cli::Run sc =
      cli::run("trace", paper + " --branch subharmonic_continuum --energy 1e-4", root / "sc");
  EXPECT_EQ(sc.code, 0) << sc.err;
  EXPECT_TRUE(fs::exists(root / "sc" / "limits.csv"));
  const cli::Run atlas = cli::run(
      "trace", paper + " --branch subharmonic_manifold --energy_min 1e-5 --energy_max 1e-4",
      root / "atlas");
  EXPECT_EQ(atlas.code, 0) << atlas.err;
  EXPECT_TRUE(fs::exists(root / "atlas" / "manifold.png"));
  fs::remove_all(root);
}

}  // namespace
