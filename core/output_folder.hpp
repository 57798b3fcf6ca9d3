// The output folder of a command, checked before any work: a bad --out is bad input (exit 2,
// nothing written) instead of a filesystem error after a long computation.
//
// check_output_folder accepts a path that is an existing writable directory, or that does not
// exist and whose nearest existing ancestor is a directory in which a folder can be created.
// It proves "can be created" by creating and removing an empty probe folder in that ancestor
// (so it leaves nothing behind); it creates nothing else. Everything else is an InputError naming
// `key`: an empty path, an existing file, an ancestor that is a file, a read-only place (/proc).
//
//   core::check_output_folder("out", "results/run1");   // ok: results/ is writable
//   core::check_output_folder("out", "paper.ini");      // InputError "out: 'paper.ini' exists
//                                                       //   and is not a directory"
//   core::check_output_folder("out", "/proc/x");        // InputError "out: cannot create
//                                                       //   '/proc/x': no folder can be
//                                                       //   created in '/proc' (...)"
#pragma once

#include <filesystem>
#include <string>

namespace backbone::core {

void check_output_folder(const std::string& key, const std::filesystem::path& folder);

}  // namespace backbone::core
