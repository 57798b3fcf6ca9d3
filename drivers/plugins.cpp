// The registry of problem plugins, filled once by the generated register_all().
#include "drivers/plugins.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/scene.hpp"

namespace backbone::drivers {

const continuation::PluginRegistry& plugins() {
  static const continuation::PluginRegistry registry = [] {
    continuation::PluginRegistry r;
    register_all(r);
    return r;
  }();
  return registry;
}

const continuation::ProblemPlugin& plugin_for_scene(const std::string& scene_path,
                                                    const std::string& what) {
  const std::string name = core::scene_problem_name(scene_path);
  const auto can = [&](const continuation::ProblemPlugin& p) {
    return what == "simulate" ? p.can_simulate() : p.can_trace();
  };
  const std::string known = plugins().names(can);
  if (name.empty())
    throw core::InputError("problem", fmt::format("the scene {} names no problem: add "
                                                  "'problem = NAME' (known: {})",
                                                  scene_path, known));
  const continuation::ProblemPlugin* plugin = plugins().find(name);
  if (!plugin || !can(*plugin))
    throw core::InputError("problem",
                           fmt::format("'{}' cannot {} (known: {})", name,
                                       what == "simulate" ? "be simulated" : "be traced", known));
  return *plugin;
}

}  // namespace backbone::drivers
