// Scenes (INI + command line, validated accessors) and atomic CSV tables.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>

#include "core/errors.hpp"
#include "core/scene.hpp"
#include "core/table.hpp"

namespace backbone::core {
namespace {

namespace fs = std::filesystem;

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("backbone_test_core_") + info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }
  fs::path dir_;
};

po::options_description bar_keys() {
  po::options_description keys("bar");
  keys.add_options()("length", po::value<double>()->default_value(1.0), "bar length L [m]")(
      "gap", po::value<double>()->default_value(1e-3), "gap g0 [m]")(
      "nodes", po::value<long>()->default_value(40), "number of nodes");
  return keys;
}

using SceneTest = TempDir;

TEST_F(SceneTest, DefaultsFileAndCommandLineMergeInThatOrder) {
  const fs::path ini = write("s.ini", "length = 2.5\ngap = 0.01\n");
  const Scene s = read_scene(bar_keys(), ini.string(), {"--gap", "0.02"}, {});
  EXPECT_EQ(s.positive("length"), 2.5);  // file beats default
  EXPECT_EQ(s.positive("gap"), 0.02);    // command line beats file
  EXPECT_EQ(s.integer("nodes", 2), 40);  // default
  EXPECT_EQ(s.path(), ini.string());
}

TEST_F(SceneTest, UnknownKeyInFileIsAnInputErrorNamingIt) {
  const fs::path ini = write("s.ini", "length = 1\nlenght = 2\n");
  try {
    read_scene(bar_keys(), ini.string(), {}, {});
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lenght"), std::string::npos) << e.what();
  }
}

TEST_F(SceneTest, UnknownKeyOnCommandLineIsAnInputError) {
  EXPECT_THROW(read_scene(bar_keys(), "", {"--nodez", "3"}, {}), InputError);
}

TEST_F(SceneTest, NanIsAnInputErrorNamingTheKey) {
  const fs::path ini = write("s.ini", "gap = nan\n");
  const Scene s = read_scene(bar_keys(), ini.string(), {}, {});
  try {
    s.number("gap");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "gap") << e.what();
  }
}

TEST_F(SceneTest, ConstraintsNameTheKey) {
  const Scene s = read_scene(bar_keys(), "", {"--length", "-1", "--nodes", "1"}, {});
  try {
    s.positive("length");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "length");
    EXPECT_NE(std::string(e.what()).find("-1"), std::string::npos) << e.what();
  }
  try {
    s.integer("nodes", 2);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "nodes");
  }
}

TEST_F(SceneTest, MissingFileIsAnInputError) {
  EXPECT_THROW(read_scene(bar_keys(), (dir_ / "absent.ini").string(), {}, {}), InputError);
  EXPECT_THROW(scene_problem_name((dir_ / "absent.ini").string()), InputError);
}

TEST_F(SceneTest, ProblemNameIsReadBeforeTheKeysAreKnown) {
  EXPECT_EQ(scene_problem_name(write("a.ini", "problem = duffing\nalpha = 1\n").string()),
            "duffing");
  EXPECT_EQ(scene_problem_name(write("b.ini", "gap = 1\n").string()), "");  // core knows no default
}

using TableTest = TempDir;

TEST_F(TableTest, CsvRoundTripIsExact) {
  Table t({"t", "u_contact"});
  t.add_row({0.0, 1e-3});
  t.add_row({0.1, -1.0 / 3.0});  // needs all 17 significant digits to round-trip
  t.add_row({std::numeric_limits<double>::denorm_min(), 6.02214076e23});
  const fs::path p = dir_ / "sub" / "history.csv";  // parent directory created on the fly
  t.write_csv(p);
  const Table back = Table::read_csv(p);
  ASSERT_EQ(back.columns(), t.columns());
  ASSERT_EQ(back.rows(), t.rows());
  for (std::size_t i = 0; i < t.rows(); ++i) EXPECT_EQ(back.row(i), t.row(i)) << "row " << i;
  EXPECT_EQ(back.column("u_contact")[1], -1.0 / 3.0);
  EXPECT_THROW(back.column("v"), InputError);
}

TEST_F(TableTest, AtomicWriteLeavesNoPartFile) {
  Table t({"a"});
  t.add_row({1.0});
  const fs::path p = dir_ / "branch.csv";
  t.write_csv(p);
  t.add_row({2.0});
  t.write_csv(p);  // overwrite in place
  EXPECT_TRUE(fs::exists(p));
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().extension(), ".csv") << entry.path();
  EXPECT_EQ(Table::read_csv(p).rows(), 2u);
}

TEST_F(TableTest, MalformedCsvIsAnInputError) {
  EXPECT_THROW(Table::read_csv(write("bad.csv", "a,b\n1,x\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("short.csv", "a,b\n1\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("trailing.csv", "a,b\n1x,2\n")), InputError);
  EXPECT_THROW(Table::read_csv(dir_ / "absent.csv"), InputError);
}

}  // namespace
}  // namespace backbone::core
