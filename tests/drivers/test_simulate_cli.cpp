// `backbone simulate` end to end: bad input is one line on stderr naming the key, exit code 2,
// and no output directory; good input writes history.csv (+ png).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/table.hpp"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int code = -1;
  std::string err;
};

// ctest runs each test in its own process, concurrently: every test gets its own folder.
fs::path scratch(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path p = fs::path(BACKBONE_BINARY_DIR) / "tests" / "simulate_cli" / info->name() / name;
  fs::remove_all(p);
  fs::create_directories(p.parent_path());
  return p;
}

CliRun simulate(const std::string& arguments, const fs::path& out) {
  const fs::path err_file = out.string() + ".stderr";
  const std::string command = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone simulate " +
                              arguments + " --out '" + out.string() + "' > /dev/null 2> '" +
                              err_file.string() + "'";
  const int status = std::system(command.c_str());
  CliRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err_file);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  fs::remove(err_file);
  return r;
}

const std::string paper =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";

void expect_bad_input(const std::string& arguments, const std::string& key) {
  const fs::path out = scratch("bad");
  const CliRun r = simulate(arguments, out);
  EXPECT_EQ(r.code, 2) << arguments << "\n" << r.err;
  EXPECT_FALSE(fs::exists(out)) << arguments;
  EXPECT_NE(r.err.find(key), std::string::npos) << arguments << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
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
  std::ofstream(ini) << "length = 1\nlenght = 2\n";
  expect_bad_input(ini.string(), "lenght");
}

TEST(SimulateCli, PaperSceneWritesHistory) {
  const fs::path out = scratch("paper");
  const CliRun r = simulate(paper + " --periods 1 --probes 0.5", out);
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
  const CliRun r = simulate(paper + " --compare --history_samples 200", out);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* m : {"tdbem", "fem", "exact"})
    EXPECT_TRUE(fs::exists(out / (std::string("history_") + m + ".csv"))) << m;
  fs::remove_all(out);
}

}  // namespace
