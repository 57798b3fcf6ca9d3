#include "continuation/cli/plugin.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
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

bool ProblemPlugin::has_branch(const std::string& branch) const {
  return std::find(branches.begin(), branches.end(), branch) != branches.end() ||
         (branch_family && branch_family(branch));
}

std::string ProblemPlugin::branch_list() const {
  std::string list = fmt::format("{}", fmt::join(branches, ", "));
  if (!branch_family_text.empty()) list += ", " + branch_family_text;
  return list;
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
