// BENCHMARKS.md from the sections of the bench cases (continuation/cli/bench_report.hpp): sections
// in the order of the case list whatever the order they were written in, a placeholder for a
// case without one, and a section rewritten by a later run.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "continuation/cli/bench_report.hpp"

using namespace backbone;

namespace {

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST(BenchReport, SectionsFollowTheCaseListAndMissingOnesGetTheirSummary) {
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / "backbone_test_bench_report";
  std::filesystem::remove_all(out);
  cli::write_bench_section(out, "second", "## Second\n\nline two");
  cli::write_bench_section(out, "first", "## First\n\nline one\n");
  const std::vector<std::pair<std::string, std::string>> cases{
      {"first", "summary one"}, {"absent", "summary absent"}, {"second", "summary two"}};
  const std::filesystem::path report = cli::write_bench_report(out, cases);
  EXPECT_EQ(report, out / "BENCHMARKS.md");
  const std::string text = read(report);
  const auto first = text.find("## First\n\nline one\n");
  const auto absent = text.find("## absent\n\nsummary absent");
  const auto second =
      text.find("## Second\n\nline two\n");  // write_bench_section adds the final newline
  ASSERT_NE(first, std::string::npos) << text;
  ASSERT_NE(absent, std::string::npos) << text;
  ASSERT_NE(second, std::string::npos) << text;
  EXPECT_LT(first, absent);
  EXPECT_LT(absent, second);
  EXPECT_EQ(text.find("summary one"), std::string::npos);  // a written section replaces it

  cli::write_bench_section(out, "first", "## First again\n");
  const std::string again = read(cli::write_bench_report(out, cases));
  EXPECT_NE(again.find("## First again\n"), std::string::npos);
  EXPECT_EQ(again.find("line one"), std::string::npos);
  EXPECT_NE(again.find("## Second"), std::string::npos);  // kept from the first report
  std::filesystem::remove_all(out);
}

TEST(BenchReport, ACaseWithoutASectionLinksItsOwnTablesAndFigures) {
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / "backbone_test_bench_report_files";
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);
  for (const char* file : {"scaling.csv", "scaling.png", "scaling_fit.csv", "scalingx.csv"})
    std::ofstream(out / file) << "x\n";
  const std::string text = read(cli::write_bench_report(
      out, {{"scaling", "cost against N"}, {"never_ran", "a case not run here"}}));
  EXPECT_NE(text.find("## scaling\n\ncost against N.\n"), std::string::npos) << text;
  EXPECT_NE(text.find("[scaling.csv](scaling.csv) [scaling_fit.csv](scaling_fit.csv)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("![scaling.png](scaling.png)"), std::string::npos) << text;
  EXPECT_EQ(text.find("scalingx.csv"), std::string::npos) << text;  // another case's file
  EXPECT_NE(text.find("## never_ran\n\na case not run here (not run into this folder"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("no section in this folder"), std::string::npos) << text;
  std::filesystem::remove_all(out);
}
