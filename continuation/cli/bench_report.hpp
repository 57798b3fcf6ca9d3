// BENCHMARKS.md, the report of `backbone bench`: one markdown section per benchmark case,
// concatenated in the order the cases are listed.
//
// A case (ProblemJob of ProblemPlugin::bench_cases, plugin.hpp) that has something to say in the
// report writes its section with write_bench_section into its output folder, as
// <out>/<case>.md: a level-2 heading, its table, one sentence saying where backbone stands, and
// links to its PNGs (relative to <out>, where BENCHMARKS.md lives too). `backbone bench` then
// calls write_bench_report with every case it knows: sections found in <out> are concatenated,
// so running one case (`--case NAME`) refreshes its own section and keeps the others. A case
// without a section file gets a heading, its summary line, and links to its tables and figures
// (<case>.csv, <case>_*.csv, <case>.png, <case>_*.png in <out>).
//
//   write_bench_section(out, "duffing_auto", "## Duffing vs AUTO-07p\n\n| ... |\n");
//   write_bench_report(out, {{"duffing_auto", "Duffing backbone vs AUTO-07p"},
//                            {"bouncing_bar", "TD-BEM and FEM vs the closed form"}});
//   // out/BENCHMARKS.md: a title, then both sections in that order
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace backbone::cli {

// <out>/<case_name>.md
std::filesystem::path bench_section_path(const std::filesystem::path& out,
                                         const std::string& case_name);

// Writes the section atomically (core::write_text_atomically), with a final newline.
void write_bench_section(const std::filesystem::path& out, const std::string& case_name,
                         const std::string& markdown);

// Writes <out>/BENCHMARKS.md from the sections of `cases` ({name, summary}, in order) and
// returns its path.
std::filesystem::path write_bench_report(
    const std::filesystem::path& out,
    const std::vector<std::pair<std::string, std::string>>& cases);

}  // namespace backbone::cli
