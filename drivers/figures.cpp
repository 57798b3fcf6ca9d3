// `backbone figures [--out DIR]`: the figures of every problem plugin
// (ProblemPlugin::figures, continuation/cli/plugin.hpp), drawn from the branches traced into DIR
// (the contact bar: the paper's Figs. 4-7 from DIR/mode1 and DIR/mode2, and
// closed_form_summary.csv).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "core/errors.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace backbone::drivers {
namespace {

namespace po = boost::program_options;

int run_figures(const std::vector<std::string>& args) {
  po::options_description keys("backbone figures");
  keys.add_options()("out", po::value<std::string>()->default_value("results"),
                     "folder holding the traced branches; the figures go there too")(
      "help", "describe the command");
  const po::variables_map vm = backbone::core::parse_options(keys, args);
  if (vm.count("help")) {
    std::ostringstream text;
    text << keys;
    fmt::print("usage: backbone figures [--out DIR]\n{}\nfigures:\n", text.str());
    for (const auto& plugin : plugins().all())
      for (const auto& f : plugin.figures)
        fmt::print("  {:<18} {} ({})\n", f.name, f.summary, plugin.name);
    return core::exit_ok;
  }
  const std::filesystem::path out = vm["out"].as<std::string>();
  if (!std::filesystem::is_directory(out))
    throw core::InputError("out", fmt::format("'{}' is not a folder of traced branches (backbone "
                                              "reproduce --out DIR writes one)",
                                              out.string()));
  // A branch one or two folders down (a problem may group its branches: DIR/PROBLEM/*/).
  bool traced = false;
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    traced = traced || std::filesystem::exists(entry.path() / "branch.csv");
    if (entry.is_directory())
      for (const auto& inner : std::filesystem::directory_iterator(entry.path()))
        traced = traced || std::filesystem::exists(inner.path() / "branch.csv");
  }
  if (!traced)
    throw core::InputError("out", fmt::format("'{}' holds no traced branch (no DIR/*/branch.csv "
                                              "or DIR/*/*/branch.csv; "
                                              "backbone reproduce --out DIR writes them)",
                                              out.string()));
  core::check_output_folder("out", out);
  int status = core::exit_ok;
  for (const auto& plugin : plugins().all())
    for (const auto& job : plugin.figures) status = std::max(status, job.run(out));
  return status;
}

}  // namespace
}  // namespace backbone::drivers

namespace backbone::drivers {

Command figures_command() {
  return {"figures", "[--out DIR]",
          "draw every problem's figures from the branches traced into DIR", run_figures};
}

}  // namespace backbone::drivers
