// Helpers of the CLI tests: run the built `backbone` binary with a subcommand, capture its exit
// code and stderr, and give each test its own scratch folder (ctest runs tests concurrently).
//
//   const fs::path out = cli::scratch("trace_cli", "bad");
//   const cli::Run r = cli::run("trace", scene + " --ds 0", out);   // adds --out OUT
//   cli::expect_bad_input("trace", scene + " --ds 0", "ds", "trace_cli");
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace cli {

namespace fs = std::filesystem;

struct Run {
  int code = -1;
  std::string err;
};

// BINARY_DIR/tests/SUITE/TEST/NAME, emptied; its parent exists.
inline fs::path scratch(const std::string& suite, const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path p = fs::path(BACKBONE_BINARY_DIR) / "tests" / suite / info->name() / name;
  fs::remove_all(p);
  fs::create_directories(p.parent_path());
  return p;
}

// The whole file, byte for byte (empty when it cannot be read).
inline std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// stderr goes to OUT.stderr, or to err_file when given (an OUT whose sibling cannot be written).
inline Run run(const std::string& subcommand, const std::string& arguments, const fs::path& out,
               fs::path err_file = {}) {
  if (err_file.empty()) err_file = out.string() + ".stderr";
  const std::string command = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone " + subcommand +
                              " " + arguments + " --out '" + out.string() + "' > /dev/null 2> '" +
                              err_file.string() + "'";
  const int status = std::system(command.c_str());
  Run r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err_file);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  fs::remove(err_file);
  return r;
}

// Bad input: exit 2, exactly one stderr line naming the key, no output folder.
inline void expect_bad_input(const std::string& subcommand, const std::string& arguments,
                             const std::string& key, const std::string& suite) {
  const fs::path out = scratch(suite, "bad");
  const Run r = run(subcommand, arguments, out);
  EXPECT_EQ(r.code, 2) << arguments << "\n" << r.err;
  EXPECT_FALSE(fs::exists(out)) << arguments;
  EXPECT_NE(r.err.find(key), std::string::npos) << arguments << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace cli
