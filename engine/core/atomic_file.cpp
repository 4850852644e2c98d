#include "engine/core/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <fstream>
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

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
  replace_file_atomically(path, [&](const std::filesystem::path& temporary) {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out)
      throw InputError(fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno)));
    write(out);
    out.flush();
    if (!out) throw InputError(fmt::format("cannot write '{}': write failed (disk full?)", path.string()));
  });
}

}  // namespace psq
