// `backbone inspect SCENE --orbit DIR/orbits.csv:K [--branch NAME] [--key value ...]`: the
// dimension of the solution set at point K of a traced branch, with its evidence (singular
// values, threshold, gap, each probe and its distance). The work is library code:
// problems/contact_bar/inspect.hpp (inspect_command, generic over the scene's plugin).
#include "problems/contact_bar/inspect.hpp"

#include "core/errors.hpp"
#include "drivers/commands.hpp"
#include "drivers/plugins.hpp"

namespace backbone::drivers {
namespace {
int run_inspect(const std::vector<std::string>& args) {
  if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
  return contact_bar::inspect_command(plugin_for_scene(args[0], "trace"), args);
}
const bool registered =
    register_command({"inspect", "SCENE --orbit DIR/orbits.csv:K",
                      "dimension of a traced point, with evidence", run_inspect});
}  // namespace
}  // namespace backbone::drivers
