// `backbone simulate` end to end: bad input is one line on stderr naming the key, exit code 2,
// and no output directory; good input writes history.csv (+ png).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/table.hpp"
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

}  // namespace
