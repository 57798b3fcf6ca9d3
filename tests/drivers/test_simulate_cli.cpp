// `backbone simulate` end to end: bad input is one line on stderr naming the key, exit code 2,
// and no output directory; good input writes history.csv (+ png).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  return cli::scratch("simulate_cli", name);
}

cli::Run simulate(const std::string& arguments, const fs::path& out) {
  return cli::run("simulate", arguments, out);
}

const std::string paper =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";

void expect_bad_input(const std::string& arguments, const std::string& key) {
  cli::expect_bad_input("simulate", arguments, key, "simulate_cli");
}

TEST(SimulateCli, BadInputExitsTwoAndWritesNothing) {
  expect_bad_input(paper + " --no_such_key 1", "no_such_key");
  expect_bad_input(paper + " --gap -1", "gap");
  expect_bad_input(paper + " --length 0", "length");
  expect_bad_input(paper + " --youngs_modulus -5", "youngs_modulus");
  expect_bad_input(paper + " --density 0", "density");
  expect_bad_input(paper + " --dt 0", "dt");
  expect_bad_input(paper + " --dt -0.1", "dt");
  expect_bad_input(paper + " --youngs_modulus nan", "youngs_modulus");
  expect_bad_input(paper + " --gap nan", "gap");
  expect_bad_input(paper + " --method magic", "method");
  expect_bad_input(paper + " --contact magic", "contact");
  expect_bad_input(paper + " --periods 0", "periods");
  expect_bad_input(paper + " --dt 2", "dt");  // TD-BEM: dt > L / c
  expect_bad_input("/no/such/scene.ini", "scene");
}

TEST(SimulateCli, UnknownKeyInSceneFile) {
  const fs::path ini = scratch("unknown.ini");
  std::ofstream(ini) << "problem = contact_bar\nlength = 1\nlenght = 2\n";
  expect_bad_input(ini.string(), "lenght");
}

TEST(SimulateCli, SceneWithoutProblemNamesTheKnownOnes) {
  // core knows no default problem: a scene must say which one it is for.
  const fs::path ini = scratch("no_problem.ini");
  std::ofstream(ini) << "length = 1\n";
  expect_bad_input(ini.string(), "problem");
  const cli::Run r = cli::run("simulate", ini.string(), scratch("no_problem_out"));
  EXPECT_NE(r.err.find("known: contact_bar"), std::string::npos) << r.err;
}

TEST(SimulateCli, PaperSceneWritesHistory) {
  const fs::path out = scratch("paper");
  const cli::Run r = simulate(paper + " --periods 1 --probes 0.5", out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto table = backbone::core::Table::read_csv(out / "history.csv");
  EXPECT_EQ(table.columns(),
            (std::vector<std::string>{"t", "u_contact", "contact_force", "energy", "u_probe0"}));
  const auto u = table.column("u_contact");
  EXPECT_NEAR(table.column("t").back(), 3.1, 1e-12);
  EXPECT_NEAR(u.back(), -0.01, 1e-12);  // mode 1 is 3.1-periodic
  fs::remove_all(out);
}

TEST(SimulateCli, CompareWritesOneHistoryPerMethod) {
  const fs::path out = scratch("compare");
  const cli::Run r = simulate(paper + " --compare --history_samples 200", out);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* m : {"tdbem", "fem", "exact"})
    EXPECT_TRUE(fs::exists(out / (std::string("history_") + m + ".csv"))) << m;
  fs::remove_all(out);
}

// FEM time steps that do not divide t_end: the history ends at t_end, its last value mode 1's
// return to u(L) = -0.01 up to the FEM's error on 100 elements, the dispersion of the mode's
// kinks (tests/problems/fem_bar), which stays below 3e-4 at these dt.
TEST(SimulateCli, FemTimeStepsThatDoNotDivideTEndReachTEnd) {
  for (const char* dt : {"0.007", "0.009", "0.008", "0.006"}) {
    const fs::path out = scratch(std::string("fem_") + dt);
    const cli::Run r = simulate(paper + " --method fem --dt " + dt, out);
    ASSERT_EQ(r.code, 0) << dt << "\n" << r.err;
    const auto table = backbone::core::Table::read_csv(out / "history.csv");
    EXPECT_NEAR(table.column("t").back(), 3.1, 1e-12) << dt;
    EXPECT_NEAR(table.column("u_contact").back(), -0.01, 3e-4) << dt;
    fs::remove_all(out);
  }
  // The bouncing bar at dt = 0.003 (t_end = 16/3 is no multiple): all three solvers reach t_end
  // (the CSV keeps 17 digits, so the value round-trips).
  const fs::path out = scratch("bouncing");
  const std::string bouncing =
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/bouncing_bar.ini";
  const cli::Run r = simulate(bouncing + " --compare --dt 0.003 --history_samples 50", out);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* m : {"tdbem", "fem", "exact"}) {
    const auto t =
        backbone::core::Table::read_csv(out / (std::string("history_") + m + ".csv")).column("t");
    EXPECT_EQ(t.back(), 5.333333333333333) << m;  // t_end = the scene's period, to the bit
  }
  fs::remove_all(out);
}

// The run's size is bounded by max_steps before anything runs: each of these runs would take
// gigabytes or minutes.
TEST(SimulateCli, RunSizeIsBoundedByMaxSteps) {
  expect_bad_input(paper + " --dt 1e-300", "dt");
  expect_bad_input(paper + " --periods 1e9", "max_steps");    // 3.1e11 steps
  expect_bad_input(paper + " --dt 1e-9", "max_steps");        // 3.1e9 steps
  expect_bad_input(paper + " --dt 1e-6", "history_samples");  // TD-BEM window x rows
  expect_bad_input(paper + " --method exact --dt 1 --periods 1e6", "periods");  // transits
  expect_bad_input(paper + " --method fem --elements 100000 --dt 1e-5", "elements");
  expect_bad_input(paper + " --max_steps 0", "max_steps");
  // The bound is exact and max_steps overrides it: the paper scene's TD-BEM run costs
  // max(311 rows, 100) x 100 window steps = 31100.
  expect_bad_input(paper + " --max_steps 31099", "max_steps");
  const fs::path out = scratch("max_steps");
  const cli::Run r = simulate(paper + " --max_steps 31100", out);
  EXPECT_EQ(r.code, 0) << r.err;
  fs::remove_all(out);
}

// Inputs that are nonsense (a folder as scene, values beyond double or int) are refused,
// naming the key.
TEST(SimulateCli, NonsenseInputIsRefused) {
  expect_bad_input(std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes", "scene");
  expect_bad_input(paper + " x", "unexpected argument 'x'");
  expect_bad_input(paper + " --length 1e100", "length");  // its energy would underflow to 0 J
  expect_bad_input(paper + " --length 1e15", "u0");       // knots 1 m apart on a 1e15 m bar
  expect_bad_input(paper + " --youngs_modulus 1e-300", "youngs_modulus");
  expect_bad_input(paper + " --periods 1e308", "periods");  // the key given, not t_end
  expect_bad_input(paper + " --history_samples 4294967298", "history_samples");
  expect_bad_input(paper + " --elements 4294967297", "elements");
}

TEST(SimulateCli, ByteOrderMarkInSceneIsSkipped) {
  const fs::path ini = scratch("bom.ini");
  std::ofstream(ini, std::ios::binary) << "\xEF\xBB\xBFproblem = contact_bar\nlength = 1\n";
  const fs::path out = scratch("bom");
  const cli::Run r = simulate(ini.string(), out);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "history.csv"));
  fs::remove_all(out);
}

// cli::run with an --out whose sibling "OUT.stderr" cannot be written: stderr goes to a scratch
// file.
cli::Run run_with_out(const std::string& command, const std::string& arguments,
                      const fs::path& out) {
  return cli::run(command, arguments, out, scratch(command + ".stderr"));
}

// A bad --out, an integer beyond int, a NaN limit are refused before any work, by trace as well
// as simulate.
TEST(SimulateCli, OutputFolderIsCheckedBeforeTheWork) {
  const fs::path file = scratch("existing.csv");
  std::ofstream(file) << "t\n0\n";
  for (const char* command : {"simulate", "trace"}) {
    for (const fs::path& bad : {file, file / "sub", fs::path("/proc/x")}) {
      const cli::Run r = run_with_out(command, paper, bad);
      EXPECT_EQ(r.code, 2) << command << " " << bad << "\n" << r.err;
      EXPECT_EQ(r.err.rfind(std::string("backbone ") + command + ": out: ", 0), 0u) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
  }
  std::ifstream in(file);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "t");  // untouched
  for (const char* key : {"max_points 4294967298", "steps_per_period 4294967298",
                          "shooting_elements 4294967297", "energy_max nan"}) {
    const std::string word(key);
    cli::expect_bad_input("trace", paper + " --" + word, word.substr(0, word.find(' ')),
                          "simulate_cli");
  }
}

// `--orbit DIR/orbits.csv:K` simulates a traced orbit over its own period: the exact oracle
// brings the contacting end back to where it started (the orbit is periodic to the trace's
// tolerance, 1e-10 g0, so 1e-9 relative to the end amplitude is a safe bound), and a point the
// branch does not have is bad input naming `orbit`.
TEST(SimulateCli, TracedOrbitReturnsOverItsPeriod) {
  const std::string branch = std::string(BACKBONE_SOURCE_DIR) + "/results/mode1";
  const fs::path out = scratch("orbit");
  const cli::Run r = simulate(paper + " --method exact --orbit " + branch + "/orbits.csv:20", out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto u = backbone::core::Table::read_csv(out / "history.csv").column("u_contact");
  ASSERT_GE(u.size(), 2u);
  EXPECT_NEAR(u.back() / u.front(), 1.0, 1e-9);
  EXPECT_LT(u.front(), -1e-3);  // in contact beyond the gap: a mode-1 orbit, not the scene's u0
  expect_bad_input(paper + " --orbit " + branch + "/orbits.csv:100000", "orbit");
  fs::remove_all(out);
}

}  // namespace
