// `backbone reproduce`: the main job. Runs every study whose figures and tables belong in
// results/ (each plugin's ProblemPlugin::reproduce steps, continuation/cli/plugin.hpp), by calling
// the other subcommands exactly as a user would, and writes a summary
// of what ran and whether it succeeded (results/reproduce.csv: step, exit_code; the wall time of
// each step is printed).
#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "core/errors.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace {

namespace po = boost::program_options;
using backbone::drivers::commands;

using backbone::cli::ReproduceStep;

// Every plugin's steps, "{out}" replaced; figures and benchmarks after the rest.
std::vector<ReproduceStep> plan(const std::string& out, bool quick) {
  std::vector<ReproduceStep> steps;
  for (const auto& plugin : backbone::drivers::plugins().all())
    for (ReproduceStep step : plugin.reproduce) {
      if (quick && step.command == "bench") continue;
      for (std::string& word : step.arguments)
        for (auto at = word.find("{out}"); at != std::string::npos;
             at = word.find("{out}", at + out.size()))
          word.replace(at, 5, out);
      steps.push_back(std::move(step));
    }
  // Figures read what the traces wrote; benchmarks come last (the longest).
  const auto rank = [](const ReproduceStep& s) {
    return s.command == "bench" ? 2 : s.command == "figures" ? 1 : 0;
  };
  std::stable_sort(steps.begin(), steps.end(),
                   [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
  return steps;
}

int run_reproduce(const std::vector<std::string>& args) {
  po::options_description keys("backbone reproduce [--out DIR] [--quick] [--only NAME]");
  keys.add_options()("help", "describe the command")(
      "out", po::value<std::string>()->default_value("results"),
      "output folder of every step's figures and tables, and of reproduce.csv")(
      "quick", po::bool_switch(), "skip the benchmarks (bench)")(
      "only", po::value<std::string>(), "run one step by name (listed below)");
  const po::variables_map vm = backbone::core::parse_options(keys, args);
  if (vm.count("help")) {
    std::string names;
    for (const ReproduceStep& s : plan("OUT", false)) names += " " + s.name;
    fmt::print("usage: backbone reproduce [--out DIR] [--quick] [--only STEP]\n{}\nsteps:{}\n",
               fmt::streamed(keys), names);
    return 0;
  }
  const std::string out = vm["out"].as<std::string>();
  std::vector<ReproduceStep> steps = plan(out, vm["quick"].as<bool>());
  if (vm.count("only")) {
    const std::string only = vm["only"].as<std::string>();
    std::erase_if(steps, [&](const ReproduceStep& s) { return s.name != only; });
    if (steps.empty())
      throw backbone::core::InputError("only", fmt::format("no step named '{}'", only));
  }
  backbone::core::check_output_folder("out", out);

  // Exit codes only: the steps' wall times vary from run to run and are printed, not tracked.
  backbone::core::Table summary({"step", "exit_code"});
  std::vector<std::string> failed;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const ReproduceStep& s = steps[i];
    fmt::print("[reproduce {}/{}] {}: backbone {} {}\n", i + 1, steps.size(), s.name, s.command,
               fmt::join(s.arguments, " "));
    std::fflush(stdout);
    const auto start = std::chrono::steady_clock::now();
    int rc = 0;
    auto it = commands().find(s.command);
    if (it == commands().end()) {
      fmt::print(stderr, "[reproduce] {}: command '{}' is not available in this build\n", s.name,
                 s.command);
      rc = 1;
    } else {
      try {
        rc = it->second.run(s.arguments);
      } catch (const std::exception& e) {
        fmt::print(stderr, "[reproduce] {}: {}\n", s.name, e.what());
        rc = dynamic_cast<const backbone::core::InputError*>(&e) ? 2 : 1;
      }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    summary.add_row({static_cast<double>(i), static_cast<double>(rc)});
    fmt::print("[reproduce {}/{}] {}: exit {} in {:.1f} s\n", i + 1, steps.size(), s.name, rc,
               seconds);
    if (rc != 0) failed.push_back(s.name);
  }
  std::string names;
  for (std::size_t i = 0; i < steps.size(); ++i)
    names += fmt::format("{} = {}\n", i, steps[i].name);
  backbone::core::write_text_atomically(std::filesystem::path(out) / "reproduce_steps.txt", names);
  summary.write_csv(std::filesystem::path(out) / "reproduce.csv");
  if (!failed.empty()) {
    fmt::print(stderr, "[reproduce] failed steps: {}\n", fmt::join(failed, ", "));
    return 1;
  }
  fmt::print("[reproduce] all {} steps succeeded; figures and tables are in {}/\n", steps.size(),
             out);
  return 0;
}

}  // namespace

namespace backbone::drivers {

Command reproduce_command() {
  return {"reproduce", "[--out DIR] [--quick] [--only STEP]",
          "reproduce every figure and table into results/", run_reproduce};
}

}  // namespace backbone::drivers
