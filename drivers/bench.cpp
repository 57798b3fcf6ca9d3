// `backbone bench [--problem NAME] [--case NAME] [--out DIR] [--threads K]`: the benchmarks of
// every problem plugin (ProblemPlugin::bench_cases, continuation/cli/plugin.hpp), not tests. Each
// case writes its CSV tables, PNG figures and its markdown section into DIR (default
// results/bench) and prints its table; DIR/BENCHMARKS.md is then rebuilt from the sections of
// every case (continuation/cli/bench_report.hpp). --threads K sets the finite-difference Jacobian
// threads of the cases that run continuation (core::set_default_jacobian_threads).
//
//   backbone bench                                  # every case of every problem
//   backbone bench --case bouncing_bar --out /tmp/bench
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>

#include "continuation/cli/bench_report.hpp"
#include "core/errors.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace backbone::drivers {
namespace {

namespace po = boost::program_options;

std::string case_names() {
  std::string list;
  for (const auto& plugin : plugins().all())
    for (const auto& c : plugin.bench_cases) list += (list.empty() ? "" : ", ") + c.name;
  return list.empty() ? "none registered" : list;
}

int run_bench(const std::vector<std::string>& args) {
  po::options_description keys("backbone bench");
  keys.add_options()("problem", po::value<std::string>(),
                     "only this problem's cases (a registered problem name)")(
      "case", po::value<std::string>(), "only this case, by name (default: all; listed below)")(
      "out", po::value<std::string>()->default_value("results/bench"),
      "output directory of the tables, figures and BENCHMARKS.md")(
      "threads", po::value<long>()->default_value(1),
      "finite-difference Jacobian threads of the cases that run continuation (1 to 256)")(
      "help", "describe the command");
  const po::variables_map vm = backbone::core::parse_options(keys, args);
  if (vm.count("help")) {
    std::ostringstream text;
    text << keys;
    fmt::print(
        "usage: backbone bench [--problem NAME] [--case NAME] [--out DIR] [--threads K]\n{}"
        "\ncases:\n",
        text.str());
    for (const auto& plugin : plugins().all())
      for (const auto& c : plugin.bench_cases)
        fmt::print("  {:<18} {} ({})\n", c.name, c.summary, plugin.name);
    return core::exit_ok;
  }
  const std::string problem = vm.count("problem") ? vm["problem"].as<std::string>() : "";
  const std::string selected = vm.count("case") ? vm["case"].as<std::string>() : "";
  if (!problem.empty() && !plugins().find(problem))
    throw core::InputError("problem",
                           fmt::format("must be one of {} (got '{}')", plugins().names(), problem));
  std::vector<const cli::ProblemJob*> jobs;
  for (const auto& plugin : plugins().all())
    for (const auto& c : plugin.bench_cases)
      if ((problem.empty() || plugin.name == problem) && (selected.empty() || c.name == selected))
        jobs.push_back(&c);
  if (!selected.empty() && jobs.empty())
    throw core::InputError("case",
                           fmt::format("must be one of {} (got '{}')", case_names(), selected));
  const long threads = vm["threads"].as<long>();
  if (threads < 1 || threads > core::max_jacobian_threads)
    throw core::InputError(
        "threads", fmt::format("must be in 1..{} (got {})", core::max_jacobian_threads, threads));
  core::set_default_jacobian_threads(static_cast<int>(threads));
  const std::filesystem::path out = vm["out"].as<std::string>();
  core::check_output_folder("out", out);
  int status = core::exit_ok;
  for (const cli::ProblemJob* job : jobs) {
    const auto start = std::chrono::steady_clock::now();
    status = std::max(status, job->run(out));
    fmt::print("bench {}: {:.1f} s\n\n", job->name,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::vector<std::pair<std::string, std::string>> all_cases;
  for (const auto& plugin : plugins().all())
    for (const auto& c : plugin.bench_cases) all_cases.emplace_back(c.name, c.summary);
  fmt::print("wrote {}\n", cli::write_bench_report(out, all_cases).string());
  return status;
}

}  // namespace
}  // namespace backbone::drivers

namespace backbone::drivers {

Command bench_command() {
  return {"bench", "[--problem NAME] [--case NAME] [--out DIR] [--threads K]",
          "benchmarks with known answers (CSV, PNG and BENCHMARKS.md in results/bench)", run_bench};
}

}  // namespace backbone::drivers
