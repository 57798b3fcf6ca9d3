// The registry of problem plugins, filled once by the executable's registration function.
#include "drivers/internal/plugins.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/io/scene.hpp"

namespace backbone::drivers {

namespace {
void (*registration)(cli::PluginRegistry&) = nullptr;
}  // namespace

void set_plugin_registration(void (*register_plugins)(cli::PluginRegistry&)) {
  registration = register_plugins;
}

const cli::PluginRegistry& plugins() {
  static const cli::PluginRegistry registry = [] {
    cli::PluginRegistry r;
    if (registration) registration(r);
    return r;
  }();
  return registry;
}

const cli::ProblemPlugin& plugin_for_scene(const std::string& scene_path, const std::string& what) {
  const std::string name = core::scene_problem_name(scene_path);
  const auto can = [&](const cli::ProblemPlugin& p) {
    return what == "simulate" ? p.can_simulate() : p.can_trace();
  };
  const std::string known = plugins().names(can);
  if (name.empty())
    throw core::InputError("problem", fmt::format("the scene {} names no problem: add "
                                                  "'problem = NAME' (known: {})",
                                                  scene_path, known));
  const cli::ProblemPlugin* plugin = plugins().find(name);
  if (!plugin || !can(*plugin))
    throw core::InputError("problem",
                           fmt::format("'{}' cannot {} (known: {})", name,
                                       what == "simulate" ? "be simulated" : "be traced", known));
  return *plugin;
}

}  // namespace backbone::drivers
