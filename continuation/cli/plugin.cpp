#include "continuation/cli/plugin.hpp"

#include <stdexcept>

namespace backbone::cli {

using namespace continuation;  // the algorithms whose settings and points this file handles

void TraceSetup::apply_branch_options(ContinuationOptions& options,
                                      core::NewtonOptions& newton) const {
  if (!branch_options) return;
  branch_options(options, newton);
  options.validate();
  newton.validate();
}

void PluginRegistry::add(ProblemPlugin plugin) {
  if (plugin.name.empty()) throw std::logic_error("a problem plugin needs a name");
  if (find(plugin.name))
    throw std::logic_error("problem plugin '" + plugin.name + "' is registered twice");
  plugins_.push_back(std::move(plugin));
}

const ProblemPlugin* PluginRegistry::find(const std::string& name) const {
  for (const ProblemPlugin& p : plugins_)
    if (p.name == name) return &p;
  return nullptr;
}

std::string PluginRegistry::names(const std::function<bool(const ProblemPlugin&)>& has) const {
  std::string list;
  for (const ProblemPlugin& p : plugins_)
    if (!has || has(p)) list += (list.empty() ? "" : ", ") + p.name;
  return list.empty() ? "none registered" : list;
}

}  // namespace backbone::cli
