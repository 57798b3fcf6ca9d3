// `backbone inspect SCENE --orbit DIR/orbits.csv:K [--branch NAME] [--key value ...]`: the
// dimension of the solution set at point K of a traced branch, with its evidence (singular
// values, threshold, gap, each probe and its distance). The work is library code,
// cli::inspect_command (continuation/cli/inspect.hpp), generic over the scene's plugin.
#include "continuation/cli/inspect.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "core/errors.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace backbone::drivers {
namespace {
constexpr const char* usage =
    "usage: backbone inspect SCENE --orbit DIR/orbits.csv:K [--branch NAME] [--key value ...]\n"
    "  the dimension of the solution set at point K of the branch traced into DIR, with its\n"
    "  evidence: singular values, threshold, gap, and each probe along a candidate null\n"
    "  direction. SCENE is usually DIR/scene.ini (the trace's grid keys); --branch defaults to\n"
    "  DIR's; any key of the scene can be given as --key value.\n";

int run_inspect(const std::vector<std::string>& args) {
  const bool help = std::find_if(args.begin(), args.end(), [](const std::string& a) {
                      return a == "--help" || a == "-h";
                    }) != args.end();
  if (help) {
    fmt::print("{}", usage);
    return core::exit_ok;
  }
  if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
  return cli::inspect_command(plugin_for_scene(args[0], "trace"), args);
}
}  // namespace

Command inspect_command() {
  return {"inspect", "SCENE --orbit DIR/orbits.csv:K", "dimension of a traced point, with evidence",
          run_inspect};
}

}  // namespace backbone::drivers
