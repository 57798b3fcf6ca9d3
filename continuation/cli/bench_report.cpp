#include "continuation/cli/bench_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <system_error>

#include "core/io/table.hpp"

namespace backbone::cli {

namespace {

// The section of a case that writes no markdown of its own: its summary, then its tables
// (<case>*.csv) and figures (<case>*.png) found in `out`, or a line saying it has not run here.
std::string files_section(const std::filesystem::path& out, const std::string& name,
                          const std::string& summary) {
  std::vector<std::string> tables, figures;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(out, error)) {
    const std::string file = entry.path().filename().string();
    if (file.rfind(name, 0) != 0) continue;
    const std::string rest = file.substr(name.size());
    if (!rest.empty() && rest[0] != '.' && rest[0] != '_') continue;  // another case's prefix
    if (entry.path().extension() == ".csv") tables.push_back(file);
    if (entry.path().extension() == ".png") figures.push_back(file);
  }
  std::sort(tables.begin(), tables.end());
  std::sort(figures.begin(), figures.end());
  if (tables.empty() && figures.empty())
    return fmt::format("## {}\n\n{} (not run into this folder: `backbone bench --case {}`).\n",
                       name, summary, name);
  std::string text = fmt::format("## {}\n\n{}.\n", name, summary);
  if (!tables.empty()) {
    text += "\nTables:";
    for (const std::string& t : tables) text += fmt::format(" [{0}]({0})", t);
    text += "\n";
  }
  for (const std::string& figure : figures) text += fmt::format("\n![{0}]({0})\n", figure);
  return text;
}

}  // namespace

std::filesystem::path bench_section_path(const std::filesystem::path& out,
                                         const std::string& case_name) {
  return out / (case_name + ".md");
}

void write_bench_section(const std::filesystem::path& out, const std::string& case_name,
                         const std::string& markdown) {
  const bool ends_in_newline = !markdown.empty() && markdown.back() == '\n';
  core::write_text_atomically(bench_section_path(out, case_name),
                              ends_in_newline ? markdown : markdown + "\n");
}

std::filesystem::path write_bench_report(
    const std::filesystem::path& out,
    const std::vector<std::pair<std::string, std::string>>& cases) {
  std::string report =
      "# Benchmarks\n\n"
      "Written by `backbone bench` (one section per case, in the order of `backbone bench "
      "--help`; a case run alone refreshes its own section). Timings are of one thread (unless "
      "`--threads K`) on the machine that ran the bench and vary by up to 3x from run to run on "
      "shared machines; the errors are deterministic. Figures and CSV tables are in "
      "this folder.\n";
  for (const auto& [name, summary] : cases) {
    const std::filesystem::path section = bench_section_path(out, name);
    std::ifstream in(section);
    report += "\n";
    if (in) {
      std::ostringstream text;
      text << in.rdbuf();
      report += text.str();
    } else {
      report += files_section(out, name, summary);
    }
  }
  const std::filesystem::path path = out / "BENCHMARKS.md";
  core::write_text_atomically(path, report);
  return path;
}

}  // namespace backbone::cli
