#include "engine/core/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <sstream>
#include <unistd.h>

#include "engine/core/error.hpp"

namespace psq {
namespace {

/// fsync of a file or directory; the error text, or empty on success.
std::string fsync_path(const std::filesystem::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) return std::strerror(errno);
  const bool synced = ::fsync(fd) == 0;
  const int error = errno;
  ::close(fd);
  return synced ? std::string() : std::strerror(error);
}

/// Creates `file` and writes `bytes` to it through a file descriptor, so that a failure is
/// reported with the system's own reason (disk full, read-only file system, permission
/// denied, file too large) rather than a stream's bare failure flag. The reason, or empty.
std::string write_new_file(const std::filesystem::path& file, std::string_view bytes) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) return std::strerror(errno);
  while (!bytes.empty()) {
    const ssize_t written = ::write(fd, bytes.data(), bytes.size());
    if (written < 0 && errno == EINTR) continue;
    if (written < 0) {
      const int error = errno;
      ::close(fd);
      return std::strerror(error);
    }
    bytes.remove_prefix(static_cast<std::size_t>(written));
  }
  return ::close(fd) == 0 ? std::string() : std::strerror(errno);
}

}  // namespace

void replace_file_atomically(const std::filesystem::path& path,
                             const std::function<void(const std::filesystem::path&)>& produce) {
  const std::filesystem::path temporary =
      path.parent_path() / fmt::format(".{}.tmp{}", path.filename().string(), ::getpid());
  const auto remove_temporary = [&] {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
  };
  const auto fail = [&](const std::string& why) {
    remove_temporary();
    return InputError(fmt::format("cannot write '{}': {}", path.string(), why));
  };
  try {
    produce(temporary);
  } catch (...) {
    remove_temporary();
    throw;
  }
  if (const std::string error = fsync_path(temporary, O_RDONLY); !error.empty())
    throw fail(fmt::format("fsync: {}", error));
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw fail(error.message());
  const std::filesystem::path dir = path.parent_path().empty() ? "." : path.parent_path();
  if (const std::string dir_error = fsync_path(dir, O_RDONLY | O_DIRECTORY); !dir_error.empty())
    throw InputError(fmt::format("cannot write '{}': fsync of its directory: {}", path.string(),
                                 dir_error));
}

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  replace_file_atomically(path, [&](const std::filesystem::path& temporary) {
    if (const std::string error = write_new_file(temporary, bytes); !error.empty())
      throw InputError(fmt::format("cannot write '{}': {}", path.string(), error));
  });
}

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
  std::ostringstream content;
  write(content);
  write_file_atomically(path, content.view());
}

}  // namespace psq
