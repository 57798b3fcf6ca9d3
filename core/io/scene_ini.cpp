#include "core/io/scene_ini.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <vector>

#include "core/errors.hpp"
#include "core/io/table.hpp"

namespace backbone::core {

std::string scene_ini_text(const Scene& scene, const std::set<std::string>& omit) {
  std::string text = fmt::format("# resolved scene of a run (scene file: {})\n", scene.path());
  for (const auto& [key, value] : scene.values()) {
    if (omit.count(key) || value.empty()) continue;
    // A key left at its default is written as a comment: read back, it is a default again, so
    // settings that depend on whether a key was given (a branch's own step defaults) are the
    // same in the resumed run.
    const std::string lead = value.defaulted() ? "# " : "";
    const std::string tail = value.defaulted() ? "  (default)\n" : "\n";
    const boost::any& v = value.value();
    if (const auto* d = boost::any_cast<double>(&v)) {
      // inf / -inf are read back by the scene reader as such; NaN never passes validation.
      text += fmt::format("{}{} = {}{}", lead, key,
                          std::isinf(*d) ? (*d > 0 ? "inf" : "-inf") : fmt::format("{}", *d), tail);
    } else if (const auto* l = boost::any_cast<long>(&v)) {
      text += fmt::format("{}{} = {}{}", lead, key, *l, tail);
    } else if (const auto* b = boost::any_cast<bool>(&v)) {
      text += fmt::format("{}{} = {}{}", lead, key, *b ? "true" : "false", tail);
    } else if (const auto* s = boost::any_cast<std::string>(&v)) {
      text += fmt::format("{}{} = {}{}", lead, key, *s, tail);
    } else if (const auto* list = boost::any_cast<std::vector<std::string>>(&v)) {
      for (const std::string& item : *list)
        text += fmt::format("{}{} = {}{}", lead, key, item, tail);
    } else {
      throw InputError(key, "has a value type the scene writer does not know");
    }
  }
  return text;
}

void write_scene_ini(const Scene& scene, const std::filesystem::path& path,
                     const std::set<std::string>& omit) {
  write_text_atomically(path, scene_ini_text(scene, omit));
}

std::string read_text_value(const std::filesystem::path& path, const std::string& key) {
  std::ifstream in(path);
  if (!in) throw InputError(key, fmt::format("cannot read '{}'", path.string()));
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key + " ", 0) == 0) return line.substr(key.size() + 1);
  throw InputError(key, fmt::format("'{}' has no line '{} ...'", path.string(), key));
}

}  // namespace backbone::core
