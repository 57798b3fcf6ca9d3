// `backbone simulate SCENE [--out DIR] [--key value ...]`: a time simulation of a scene, by the
// problem its `problem` key names (continuation/cli/plugin.hpp: ProblemPlugin::simulate). The
// contact bar's keys (--method tdbem|fem|exact|all, --periods P, --compare) are described by
// `backbone simulate SCENE --help`. The problem validates everything and runs before it
// creates DIR: bad input writes nothing (exit 2), a numerical failure writes nothing (exit 1).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "continuation/cli/scene_options.hpp"
#include "core/errors.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace backbone::drivers {
namespace {

namespace po = boost::program_options;
namespace fs = std::filesystem;

const char* const usage = "SCENE [--out DIR] [--key value ...]";

po::options_description driver_keys() {
  po::options_description keys("simulate");
  keys.add_options()(
      "out", po::value<std::string>()->default_value("simulate_out"),
      "output directory DIR (existing or creatable; written after a successful run)")(
      "help", po::bool_switch(), "print the keys and exit");
  return keys;
}

int run_simulate(const std::vector<std::string>& args) {
  const bool help = std::any_of(args.begin(), args.end(),
                                [](const std::string& a) { return a == "--help" || a == "-h"; });
  if (args.empty() || args[0].rfind("-", 0) == 0) {
    if (help) {
      fmt::print("usage: backbone simulate {}\n\nproblems that simulate: {}\n{}\n", usage,
                 plugins().names([](const auto& p) { return p.can_simulate(); }),
                 "(their keys: backbone simulate SCENE --help)");
      return core::exit_ok;
    }
    throw core::InputError("scene", "the first argument must be the scene file (SCENE)");
  }
  const std::string scene_path = args[0];
  const cli::ProblemPlugin& plugin = plugin_for_scene(scene_path, "simulate");
  if (help) {
    std::ostringstream keys;
    keys << driver_keys() << "\n" << plugin.simulate_keys();
    fmt::print("usage: backbone simulate {}\n\n{}", usage, keys.str());
    return core::exit_ok;
  }
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  po::options_description keys = plugin.simulate_keys();
  // A scene.ini written by `trace` holds trace keys: read from the file, refused on the line.
  const po::options_description trace_only = cli::trace_keys_beyond(plugin, keys);
  for (const auto& option : trace_only.options())
    if (cli::given_on_command_line(rest, option->long_name()))
      throw core::InputError(option->long_name(),
                             "is a key of `backbone trace`; a simulation does not use it");
  keys.add(trace_only);
  const core::Scene scene = core::read_scene(keys, scene_path, rest, driver_keys());
  const fs::path out(scene.text("out"));
  core::check_output_folder("out", out);
  const int code = plugin.simulate(scene, out);
  if (code == core::exit_ok) fmt::print("wrote {}\n", out.string());
  return code;
}

}  // namespace

Command simulate_command() {
  return {"simulate", usage, "time simulation of a scene (the problem's solvers)", run_simulate};
}

}  // namespace backbone::drivers
