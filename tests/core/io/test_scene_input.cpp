// The scene reader and the output-folder check against inputs that are easy to get wrong:
// integers beyond the int range, a directory as the scene, stray words on the
// command line, a UTF-8 byte-order mark, and output folders that cannot be written. Each is an
// InputError naming its key before any work, or (the byte-order mark) read correctly.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "core/errors.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene.hpp"

namespace backbone::core {
namespace {

namespace fs = std::filesystem;

class SceneInput : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / (std::string("backbone_test_scene_input_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  // Every entry of dir_, so that a test can assert the check left nothing behind.
  std::size_t entries() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), {}));
  }
  fs::path dir_;
};

po::options_description keys() {
  po::options_description k("test");
  k.add_options()("problem", po::value<std::string>(), "problem")(
      "points", po::value<long>()->default_value(10), "points")(
      "length", po::value<double>()->default_value(1.0), "length [m]")("verbose", po::bool_switch(),
                                                                       "a flag");
  return k;
}

// The message of the InputError `f` throws ("" if none), with its key checked.
template <class F>
std::string input_error(F&& f, const std::string& key) {
  try {
    f();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no InputError for key " << key;
  return "";
}

// 4294967298 = 2^32 + 2: a cast to int would read it as 2.
TEST_F(SceneInput, IntegerAboveIntMaxNamesTheKeyAndTheBound) {
  const Scene s = read_scene(keys(), "", {"--points", "4294967298"}, {});
  EXPECT_EQ(input_error([&] { s.integer("points", 1); }, "points"),
            "points: must be <= 2147483647 (got 4294967298)");
  const Scene at_max = read_scene(keys(), "", {"--points", "2147483647"}, {});
  EXPECT_EQ(at_max.integer("points", 1), std::numeric_limits<int>::max());
  // An explicit bound, as the contact bar gives its element count.
  const Scene big = read_scene(keys(), "", {"--points", "100000001"}, {});
  EXPECT_EQ(input_error([&] { big.integer("points", 1, 100'000'000); }, "points"),
            "points: must be <= 100000000 (got 100000001)");
  // 2^32 + 1 reads as 1 through an int: the old "must be >= 2 (got 1)" named the wrong value.
  const Scene wrapped = read_scene(keys(), "", {"--points", "4294967297"}, {});
  EXPECT_NE(input_error([&] { wrapped.integer("points", 2); }, "points").find("4294967297"),
            std::string::npos);
}

// A shipped scene named relative to the source tree reads from any working directory; a
// relative path found in neither place is still an InputError naming the scene.
TEST_F(SceneInput, ShippedSceneReadsFromAnyDirectory) {
  const fs::path here = fs::current_path();
  fs::current_path(dir_);
  ASSERT_FALSE(fs::exists("problems/duffing/scenes/duffing.ini"));
  ASSERT_TRUE(fs::exists(fs::path(BACKBONE_SOURCE_DIR) / "problems/duffing/scenes/duffing.ini"));
  std::string name;
  try {
    name = scene_problem_name("problems/duffing/scenes/duffing.ini");
  } catch (...) {
    fs::current_path(here);
    throw;
  }
  const std::string message =
      input_error([] { scene_problem_name("problems/duffing/scenes/no_such.ini"); }, "scene");
  fs::current_path(here);
  EXPECT_EQ(name, "duffing");
  EXPECT_NE(message.find("cannot read scene file"), std::string::npos) << message;
}

TEST_F(SceneInput, DirectoryAsSceneIsRefused) {
  const std::string message =
      input_error([&] { read_scene(keys(), dir_.string(), {}, {}); }, "scene");
  EXPECT_NE(message.find("is a directory"), std::string::npos) << message;
  input_error([&] { scene_problem_name(dir_.string()); }, "scene");
}

TEST_F(SceneInput, StrayCommandLineWordIsRefused) {
  const std::string message = input_error(
      [&] {
        read_scene(keys(), "", {"--length", "2", "x"}, {});
      },
      "command line");
  EXPECT_NE(message.find("unexpected argument 'x'"), std::string::npos) << message;
  // After a flag too: --verbose takes no value, so "yes" is a stray word, named with the flag.
  const std::string after_flag = input_error(
      [&] {
        read_scene(keys(), "", {"--verbose", "yes"}, {});
      },
      "verbose");
  EXPECT_NE(after_flag.find("takes no value (got 'yes' after it)"), std::string::npos)
      << after_flag;
  // A key that needs a value, followed by another key, is named with its own.
  input_error([&] { read_scene(keys(), "", {"--length", "--points", "3"}, {}); }, "length");
  input_error([&] { read_scene(keys(), "", {"--points"}, {}); }, "points");
  // Negative values are still values.
  EXPECT_EQ(read_scene(keys(), "", {"--length", "-2"}, {}).number("length"), -2.0);
}

TEST_F(SceneInput, ByteOrderMarkIsSkipped) {
  const fs::path ini = write("bom.ini", "\xEF\xBB\xBFproblem = demo\nlength = 2.5\n");
  const Scene s = read_scene(keys(), ini.string(), {}, {});
  EXPECT_EQ(s.text("problem"), "demo");
  EXPECT_EQ(s.number("length"), 2.5);
  EXPECT_EQ(scene_problem_name(ini.string()), "demo");
  // Only at the start: elsewhere the bytes stay part of the text (an unknown key).
  const fs::path inside = write("inside.ini", "length = 2.5\n\xEF\xBB\xBFpoints = 3\n");
  EXPECT_THROW(read_scene(keys(), inside.string(), {}, {}), InputError);
}

// Boost's message template replaces %value% with the value until none is left, so a value
// holding "%value%" looped for ever (a libFuzzer timeout, tests/fuzz/corpus/scene/
// percent_placeholder). Now it is refused at once, quoted with a lookalike percent sign.
TEST_F(SceneInput, ValueHoldingABoostPlaceholderIsRefusedWithoutHanging) {
  const fs::path ini = write("percent.ini", "length = %value%'\n");
  const std::string in_file =
      input_error([&] { read_scene(keys(), ini.string(), {}, {}); }, "length");
  EXPECT_NE(in_file.find("length"), std::string::npos) << in_file;
  const std::string on_line = input_error(
      [&] {
        read_scene(keys(), "", {"--points", "%value%"}, {});
      },
      "points");
  EXPECT_NE(on_line.find("points"), std::string::npos) << on_line;
}

TEST_F(SceneInput, OutputFolderThatCanBeCreatedPassesAndLeavesNothing) {
  EXPECT_NO_THROW(check_output_folder("out", dir_ / "new" / "deeper"));
  EXPECT_NO_THROW(check_output_folder("out", dir_));  // an existing writable directory
  EXPECT_EQ(entries(), 0u);                           // no probe left behind
  EXPECT_FALSE(fs::exists(dir_ / "new"));
}

TEST_F(SceneInput, OutputFolderThatCannotBeWrittenIsRefused) {
  const fs::path file = write("file.csv", "t\n0\n");
  EXPECT_NE(
      input_error([&] { check_output_folder("out", file); }, "out").find("is not a directory"),
      std::string::npos);
  EXPECT_NE(input_error([&] { check_output_folder("out", file / "sub"); }, "out")
                .find("is not a directory"),
            std::string::npos);
  input_error([&] { check_output_folder("out", ""); }, "out");
  // /proc refuses new entries even to root (a permission check alone would pass as root).
  if (fs::is_directory("/proc")) input_error([&] { check_output_folder("out", "/proc/x"); }, "out");
  EXPECT_EQ(entries(), 1u);  // only file.csv
}

}  // namespace
}  // namespace backbone::core
