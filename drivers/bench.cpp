// `backbone bench [--case NAME] [--out DIR]`: the contact bar's benchmark cases
// (problems/contact_bar/bench.hpp), all or the one named, and the time each took.
#include "problems/contact_bar/bench.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <boost/program_options.hpp>
#include <chrono>

#include "core/errors.hpp"
#include "drivers/commands.hpp"

namespace {

namespace po = boost::program_options;
namespace core = backbone::core;

int run_bench(const std::vector<std::string>& args) {
  const auto cases = backbone::contact_bar::bench_cases();
  std::string names;  // "tdbem_scaling, bouncing_bar, ...": for --help and errors
  for (const auto& c : cases) names += (names.empty() ? "" : ", ") + c.name;
  po::options_description keys("backbone bench");
  keys.add_options()("case", po::value<std::string>(),
                     ("one of " + names + " (default: all)").c_str())(
      "out", po::value<std::string>()->default_value("results/bench"), "output directory")(
      "help", "describe the command");
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(args).options(keys).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw core::InputError("", e.what());
  }
  if (vm.count("help")) {
    fmt::print("usage: backbone bench [--case NAME] [--out DIR]\n{}", fmt::streamed(keys));
    return 0;
  }
  const std::string selected = vm.count("case") ? vm["case"].as<std::string>() : "";
  if (!selected.empty() &&
      std::none_of(cases.begin(), cases.end(), [&](const auto& c) { return c.name == selected; }))
    throw core::InputError("case", fmt::format("must be one of {} (got '{}')", names, selected));
  int status = 0;
  for (const auto& c : cases) {
    if (!selected.empty() && c.name != selected) continue;
    const auto start = std::chrono::steady_clock::now();
    status = std::max(status, c.run(vm["out"].as<std::string>()));
    const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start;
    fmt::print("bench {}: {:.1f} s\n\n", c.name, seconds.count());
  }
  return status;
}

}  // namespace

static const bool registered = backbone::drivers::register_command(
    {"bench", "[--case NAME] [--out DIR]", "benchmarks with known answers (results/bench)",
     run_bench});
