// `backbone inspect SCENE --orbit DIR/orbits.csv:K [--branch NAME] [--key value ...]`: the
// dimension of the solution set at point K of a traced branch, with its evidence (singular
// values, threshold, gap, each probe and its distance). The work is library code,
// cli::inspect_command (continuation/cli/inspect.hpp), generic over the scene's plugin.
#include "continuation/cli/inspect.hpp"

#include "core/errors.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace backbone::drivers {
namespace {
int run_inspect(const std::vector<std::string>& args) {
  if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
  return cli::inspect_command(plugin_for_scene(args[0], "trace"), args);
}
}  // namespace

Command inspect_command() {
  return {"inspect", "SCENE --orbit DIR/orbits.csv:K", "dimension of a traced point, with evidence",
          run_inspect};
}

}  // namespace backbone::drivers
