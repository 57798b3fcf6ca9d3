// A resolved scene written back as an INI file that reproduces the run.
//
// Every key of a parsed core::Scene (defaults, scene file and command line merged) is written
// as `key = value`, one per line, in the flat syntax read_scene reads; numbers in their
// shortest round-trip form, so reading the file back gives the same values bit for bit. A key
// at its default is written as a comment, `# key = value  (default)`: read back it is a default
// again (same value, and still "not given"). Keys named in `omit` (driver options such as out,
// resume, help) are left out. Written atomically.
//
//   core::write_scene_ini(scene, out / "scene.ini", {"out", "help"});
//   // later: backbone trace out/scene.ini --out again   (the same run)
#pragma once

#include <filesystem>
#include <set>
#include <string>

#include "core/io/scene.hpp"

namespace backbone::core {

// The INI text of the scene (without the omitted keys); a value of a type other than double,
// long, bool, string or a list of strings is an InputError naming its key.
std::string scene_ini_text(const Scene& scene, const std::set<std::string>& omit);
void write_scene_ini(const Scene& scene, const std::filesystem::path& path,
                     const std::set<std::string>& omit);

// The value of a `key value` line of a plain summary file (summary.txt of a trace): InputError
// naming `key` when the file or the line is missing.
std::string read_text_value(const std::filesystem::path& path, const std::string& key);

}  // namespace backbone::core
