#include "continuation/cli/bench_report.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "core/table.hpp"

namespace backbone::cli {


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
      report += fmt::format(
          "## {}\n\n{} (no section in this folder: the case writes none, or has not run here).\n",
          name, summary);
    }
  }
  const std::filesystem::path path = out / "BENCHMARKS.md";
  core::write_text_atomically(path, report);
  return path;
}

}  // namespace backbone::cli
