// Scenes (INI + command line, validated accessors) and atomic CSV tables.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"

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

// A numeric table's CSV is plain numbers with 17 significant digits, as before texts existed.
TEST_F(TableTest, NumericCsvTextIsPlainNumbers) {
  Table t({"a", "b"});
  t.add_row({0.1, 2.0});
  t.add_row({std::nan(""), -std::numeric_limits<double>::infinity()});
  EXPECT_EQ(t.csv(), "a,b\n0.10000000000000001,2\nnan,-inf\n");
  const fs::path p = dir_ / "numbers.csv";
  t.write_csv(p);
  const Table back = Table::read_csv(p);
  EXPECT_TRUE(std::isnan(back.column("a")[1]));
  EXPECT_EQ(back.column("b")[1], -std::numeric_limits<double>::infinity());
}

// Texts survive write + read exactly, including the ones CSV must quote: commas, quotes, line
// breaks, the empty text and texts that would read back as numbers.
TEST_F(TableTest, MixedCsvRoundTripIsExact) {
  Table t({"method", "dt", "error", "note"});
  t.add_cells({"tdbem", 1e-3, -1.0 / 3.0, "plain"});
  t.add_cells(
      {"fem, consistent", 0.1, std::numeric_limits<double>::denorm_min(), "say \"hi\"\nnext line"});
  t.add_cells({"1e-3", 6.02214076e23, 0.0, ""});
  t.add_row("label", {1.0, 2.0, 3.0});  // TextTable's form: a text label, then numbers
  const std::string csv = t.csv();
  EXPECT_NE(csv.find("\ntdbem,0.001,"), std::string::npos) << csv;  // plain text unquoted
  EXPECT_NE(csv.find("\"fem, consistent\""), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"say \"\"hi\"\"\nnext line\""), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"1e-3\""), std::string::npos) << csv;
  EXPECT_NE(csv.find(",\"\"\n"), std::string::npos) << csv;

  const fs::path p = dir_ / "mixed.csv";
  t.write_csv(p);
  const Table back = Table::read_csv(p);
  ASSERT_EQ(back.columns(), t.columns());
  ASSERT_EQ(back.rows(), t.rows());
  for (std::size_t i = 0; i < t.rows(); ++i) EXPECT_EQ(back.cells(i), t.cells(i)) << "row " << i;
  EXPECT_EQ(back.text_column("method"),
            (std::vector<std::string>{"tdbem", "fem, consistent", "1e-3", "label"}));
  EXPECT_EQ(back.column("error")[0], -1.0 / 3.0);
  // Numbers read as texts keep the spelling write_csv gives them.
  EXPECT_EQ(back.text_column("dt"), (std::vector<std::string>{"0.001", "0.10000000000000001",
                                                              "6.0221407599999999e+23", "1"}));
}

TEST_F(TableTest, TextWhereNumbersAreExpectedIsAnInputError) {
  Table t({"method", "dt"});
  t.add_row("fem", {1e-3});
  t.add_row({2.0, 2e-3});  // a number in a text column is fine for text_column
  EXPECT_EQ(t.text_column("method"), (std::vector<std::string>{"fem", "2"}));
  EXPECT_EQ(t.column("dt"), (std::vector<double>{1e-3, 2e-3}));
  EXPECT_EQ(t.row(1), (std::vector<double>{2.0, 2e-3}));
  try {
    t.column("method");
    ADD_FAILURE() << "column() of a text column";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "method");
  }
  EXPECT_THROW(t.row(0), InputError);
  EXPECT_THROW(t.text_column("absent"), InputError);
  EXPECT_THROW(t.add_cells({"only one cell"}), std::logic_error);
  EXPECT_THROW(t.add_row("label", {1.0, 2.0}), std::logic_error);
}

// Hand-written files: unquoted cells are numbers when they parse fully, texts otherwise;
// quoted cells are texts; CRLF line ends and blank lines are accepted.
TEST_F(TableTest, ReadCsvSortsNumbersFromTexts) {
  const Table t =
      Table::read_csv(write("hand.csv", "name,value\r\nx,1\r\n\r\n\"2\",3e-1\r\n1x,nan\r\n"));
  ASSERT_EQ(t.rows(), 3u);
  EXPECT_EQ(t.text_column("name"), (std::vector<std::string>{"x", "2", "1x"}));
  EXPECT_EQ(t.cells(1)[0], Table::Cell(std::string("2")));
  const std::vector<double> value = t.column("value");
  EXPECT_EQ(value[0], 1.0);
  EXPECT_EQ(value[1], 0.3);
  EXPECT_TRUE(std::isnan(value[2]));
  EXPECT_THROW(t.column("name"), InputError);
}

TEST_F(TableTest, AlignedRendersRightAlignedColumns) {
  Table t({"method", "dt"});
  t.add_row("fem", {0.123456789});
  t.add_row("tdbem", {1e-7});
  EXPECT_EQ(t.aligned(), "  method        dt\n     fem  0.123457\n   tdbem     1e-07\n");
  EXPECT_EQ(t.aligned(2), "  method     dt\n     fem   0.12\n   tdbem  1e-07\n");
}

TEST_F(TableTest, MalformedCsvIsAnInputError) {
  EXPECT_THROW(Table::read_csv(write("short.csv", "a,b\n1\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("long.csv", "a,b\n1,2,3\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("unterminated.csv", "a,b\n\"1,2\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("after_quote.csv", "a,b\n\"1\"x,2\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("inner_quote.csv", "a,b\n1\"x,2\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("overflow.csv", "a,b\n1e999,2\n")), InputError);
  EXPECT_THROW(Table::read_csv(write("empty.csv", "")), InputError);
  EXPECT_THROW(Table::read_csv(dir_ / "absent.csv"), InputError);
  try {
    Table::read_csv(write("where.csv", "a,b\n1,2\n3\n"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("where.csv:3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace backbone::core
