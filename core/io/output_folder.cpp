#include "core/io/output_folder.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstring>
#include <system_error>

#include "core/errors.hpp"

namespace backbone::core {

namespace fs = std::filesystem;

namespace {

// Creates and removes an empty folder inside `directory`; the error if that fails.
std::error_code probe_folder_creation(const fs::path& directory) {
  static std::atomic<unsigned> counter{0};
  const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  const fs::path probe =
      directory / fmt::format(".backbone_probe_{}_{}_{}", ::getpid(), counter++, stamp);
  std::error_code error;
  if (!fs::create_directory(probe, error) && !error)
    error = std::make_error_code(std::errc::file_exists);
  if (error) return error;
  fs::remove(probe, error);
  return error;
}

}  // namespace

void check_output_folder(const std::string& key, const fs::path& folder) {
  if (folder.empty()) throw InputError(key, "must not be empty");
  // The system's limits on a path and on each name in it (PATH_MAX, NAME_MAX).
  std::error_code absolute_error;
  const std::string whole = fs::absolute(folder, absolute_error).string();
  if (whole.size() >= PATH_MAX)
    throw InputError(key, fmt::format("the path is {} characters long, more than the system's "
                                      "limit of {}",
                                      whole.size(), PATH_MAX - 1));
  for (const fs::path& name : folder)
    if (name.string().size() > NAME_MAX)
      throw InputError(key, fmt::format("a folder name of {} characters is longer than the "
                                        "system's limit of {}",
                                        name.string().size(), NAME_MAX));
  std::error_code error;
  const fs::file_status status = fs::status(folder, error);
  if (fs::exists(status)) {
    if (!fs::is_directory(status))
      throw InputError(key, fmt::format("'{}' exists and is not a directory", folder.string()));
    if (const std::error_code e = probe_folder_creation(folder))
      throw InputError(key,
                       fmt::format("cannot write into '{}' ({})", folder.string(), e.message()));
    return;
  }
  // The nearest existing ancestor must be a directory in which a folder can be created.
  fs::path ancestor = fs::absolute(folder, error).parent_path();
  while (!ancestor.empty() && !fs::exists(ancestor, error) && ancestor != ancestor.parent_path())
    ancestor = ancestor.parent_path();
  if (!fs::is_directory(ancestor, error))
    throw InputError(key, fmt::format("cannot create '{}': '{}' is not a directory",
                                      folder.string(), ancestor.string()));
  if (const std::error_code e = probe_folder_creation(ancestor))
    throw InputError(key, fmt::format("cannot create '{}': no folder can be created in '{}' ({})",
                                      folder.string(), ancestor.string(), e.message()));
}

FolderLock::FolderLock(const std::string& key, const fs::path& folder) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  fd_ = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    throw InputError(key, fmt::format("cannot open the folder '{}' ({})", folder.string(),
                                      std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    throw InputError(key, error == EWOULDBLOCK
                              ? fmt::format("another run is writing into '{}'", folder.string())
                              : fmt::format("cannot lock the folder '{}' ({})", folder.string(),
                                            std::strerror(error)));
  }
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the descriptor releases the lock
}

}  // namespace backbone::core
