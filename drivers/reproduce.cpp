// `backbone reproduce`: the main job. Runs every study whose figures and tables belong in
// results/, by calling the other subcommands exactly as a user would, and writes a summary
// of what ran, how long it took and whether it succeeded (results/reproduce.csv).
#include <fmt/format.h>
#include <fmt/ostream.h>

#include <chrono>
#include <filesystem>

#include "core/errors.hpp"
#include "core/scene.hpp"
#include "core/table.hpp"
#include "drivers/commands.hpp"

namespace {

namespace po = boost::program_options;
using backbone::drivers::commands;

struct Step {
  std::string name;
  std::string command;
  std::vector<std::string> args;
};

std::vector<Step> plan(const std::string& out, bool quick) {
  const std::string contact = "problems/contact_bar/scenes/";
  std::vector<Step> steps{
      {"bouncing_bar",
       "simulate",
       {contact + "bouncing_bar.ini", "--compare", "--periods", "2", "--out",
        out + "/bouncing_bar"}},
      {"mode1_orbit",
       "simulate",
       {contact + "paper.ini", "--compare", "--periods", "1", "--out", out + "/mode1_orbit"}},
      {"duffing",
       "trace",
       {"problems/duffing/scenes/duffing.ini", "--branch", "backbone", "--out", out + "/duffing"}},
      {"mode1", "trace", {contact + "paper.ini", "--branch", "mode1", "--out", out + "/mode1"}},
      {"mode2", "trace", {contact + "paper.ini", "--branch", "mode2", "--out", out + "/mode2"}},
      // Other scenes, nothing but the bar changed: the closed forms must hold there too.
      {"mode1_short_bar",
       "trace",
       {contact + "paper.ini", "--branch", "mode1", "--length", "0.3", "--youngs_modulus", "7e4",
        "--density", "2.7", "--gap", "1e-5", "--out", out + "/mode1_short_bar"}},
      {"mode2_steel_bar",
       "trace",
       {contact + "paper.ini", "--branch", "mode2", "--length", "2.5", "--youngs_modulus", "2.1e11",
        "--density", "7850", "--area", "3e-4", "--gap", "1e-4", "--energy_max", "1e3", "--out",
        out + "/mode2_steel_bar"}},
      {"figures", "figures", {"--out", out}},
  };
  if (!quick) steps.push_back({"bench", "bench", {"--out", out + "/bench"}});
  return steps;
}

int run_reproduce(const std::vector<std::string>& args) {
  po::options_description keys("backbone reproduce [--out DIR] [--quick] [--only NAME]");
  keys.add_options()("help", "describe the command")(
      "out", po::value<std::string>()->default_value("results"), "output folder")(
      "quick", po::bool_switch(), "skip the benchmarks (bench)")("only", po::value<std::string>(),
                                                                 "run one step by name");
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(args).options(keys).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw backbone::core::InputError("", e.what());
  }
  if (vm.count("help")) {
    fmt::print(
        "{}\nsteps: bouncing_bar mode1_orbit duffing mode1 mode2 mode1_short_bar mode2_steel_bar "
        "figures bench\n",
        fmt::streamed(keys));
    return 0;
  }
  const std::string out = vm["out"].as<std::string>();
  std::vector<Step> steps = plan(out, vm["quick"].as<bool>());
  if (vm.count("only")) {
    const std::string only = vm["only"].as<std::string>();
    std::erase_if(steps, [&](const Step& s) { return s.name != only; });
    if (steps.empty())
      throw backbone::core::InputError("only", fmt::format("no step named '{}'", only));
  }

  backbone::core::Table summary({"step", "exit_code", "seconds"});
  std::vector<std::string> failed;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const Step& s = steps[i];
    fmt::print("[reproduce {}/{}] {}: backbone {} {}\n", i + 1, steps.size(), s.name, s.command,
               fmt::join(s.args, " "));
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
        rc = it->second.run(s.args);
      } catch (const std::exception& e) {
        fmt::print(stderr, "[reproduce] {}: {}\n", s.name, e.what());
        rc = dynamic_cast<const backbone::core::InputError*>(&e) ? 2 : 1;
      }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    summary.add_row({static_cast<double>(i), static_cast<double>(rc), seconds});
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

static const bool registered = backbone::drivers::register_command(
    {"reproduce", "[--out DIR] [--quick] [--only STEP]",
     "reproduce every figure and table into results/", run_reproduce});
