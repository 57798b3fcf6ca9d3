// `backbone figures [--out DIR]`: the contact bar's figure jobs (problems/contact_bar/
// figures.hpp), drawn from the trace outputs OUT/mode1 and OUT/mode2 into OUT.
#include "problems/contact_bar/figures.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <boost/program_options.hpp>

#include "core/errors.hpp"
#include "drivers/commands.hpp"

namespace {

namespace po = boost::program_options;
using namespace backbone;

int run_figures(const std::vector<std::string>& args) {
  po::options_description keys("backbone figures [--out DIR]");
  keys.add_options()("help", "describe the command")(
      "out", po::value<std::string>()->default_value("results"), "output folder");
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(args).options(keys).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw core::InputError("", e.what());
  }
  if (vm.count("help")) {
    fmt::print("{}", fmt::streamed(keys));
    return 0;
  }
  int status = 0;
  for (const continuation::ProblemJob& job : contact_bar::figure_jobs()) {
    status = std::max(status, job.run(vm["out"].as<std::string>()));
    if (status != 0) break;  // no branch to draw from: say so once
  }
  return status;
}

}  // namespace

static const bool registered = backbone::drivers::register_command(
    {"figures", "[--out DIR]",
     "draw the contact-bar mode figures (backbones, contact history, space-time)", run_figures});
