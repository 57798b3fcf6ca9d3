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
//
// FolderLock makes one process at a time the writer of a folder: it creates the folder and holds
// an exclusive advisory lock (flock) on it while it lives; a second writer's lock is refused at
// once with an InputError naming `key`. The lock goes with the process, so a killed run leaves
// no stale lock behind.
//
//   core::FolderLock lock("out", "results/run1");   // InputError "out: another run is writing
//                                                   //   into 'results/run1'" while one does
#pragma once

#include <filesystem>
#include <string>

namespace backbone::core {

void check_output_folder(const std::string& key, const std::filesystem::path& folder);

class FolderLock {
 public:
  FolderLock(const std::string& key, const std::filesystem::path& folder);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace backbone::core
