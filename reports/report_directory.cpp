#include "reports/report_directory.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"

namespace psq::reports {
namespace {

std::filesystem::path absolute_target(const std::filesystem::path& target) {
  std::error_code error;
  std::filesystem::path path = std::filesystem::absolute(target, error).lexically_normal();
  if (error || path.filename().empty()) path = path.parent_path();  // a trailing '/'
  if (error || path.filename().empty() || path == path.root_path())
    throw InputError(
        fmt::format("cannot write a report to '{}': name a directory to create", target.string()));
  return path;
}

/// Throws unless `target` is absent, an empty directory or an earlier report.
void check_replaceable(const std::filesystem::path& target) {
  std::error_code error;
  const auto status = std::filesystem::symlink_status(target, error);
  if (!std::filesystem::exists(status)) return;
  if (!std::filesystem::is_directory(status))
    throw InputError(
        fmt::format("cannot write a report to '{}': it exists and is not a "
                    "directory",
                    target.string()));
  if (std::filesystem::is_empty(target, error) ||
      std::filesystem::exists(target / kReportMarker, error))
    return;
  throw InputError(
      fmt::format("refusing to replace '{}': it is a non-empty directory that psq "
                  "did not write (no {} file); choose another --out or remove it",
                  target.string(), kReportMarker));
}

void sync_directory(const std::filesystem::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

/// Puts `built` in place of `target`. An existing target is exchanged atomically where the
/// file system supports it, else moved aside first; `built` then holds the old content.
/// Returns false if `target` did not exist.
bool move_into_place(const std::filesystem::path& built, const std::filesystem::path& target) {
  std::error_code error;
  if (!std::filesystem::exists(target)) {
    std::filesystem::rename(built, target, error);
    if (error)
      throw InputError(fmt::format("cannot write '{}': {}", target.string(), error.message()));
    return false;
  }
  if (::renameat2(AT_FDCWD, built.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0)
    return true;
  const std::filesystem::path aside = built.string() + ".old";
  std::filesystem::rename(target, aside, error);
  if (!error) {
    std::filesystem::rename(built, target, error);
    if (error) {
      std::filesystem::rename(aside, target);
    } else {
      std::filesystem::rename(aside, built, error);
      return true;
    }
  }
  throw InputError(fmt::format("cannot replace '{}': {}", target.string(), error.message()));
}

}  // namespace

void publish_directory(const std::filesystem::path& target,
                       const std::function<void(const std::filesystem::path&)>& fill) {
  const std::filesystem::path path = absolute_target(target);
  check_replaceable(path);
  std::error_code error;
  std::filesystem::create_directories(path.parent_path(), error);
  if (error)
    throw InputError(
        fmt::format("cannot write a report to '{}': cannot create its parent "
                    "directory: {}",
                    target.string(), error.message()));
  const std::filesystem::path built =
      path.parent_path() / fmt::format(".{}.tmp{}", path.filename().string(), ::getpid());
  std::filesystem::remove_all(built, error);
  if (!std::filesystem::create_directory(built, error) || error)
    throw InputError(fmt::format("cannot write a report to '{}': {}", target.string(),
                                 error ? error.message() : "a temporary directory is in the way"));
  // The report is built whole before it replaces anything: until then, a failure (a file that
  // cannot be written on a full or read-only disk, and the like) leaves `target` as it was.
  const auto failed = [&](const std::string& why) {
    std::filesystem::remove_all(built, error);
    return InputError(fmt::format("cannot write a report to '{}': {}; '{}' is left as it was",
                                  target.string(), why, target.string()));
  };
  try {
    fill(built);
    write_file_atomically(built / kReportMarker, std::string_view("written by psq report\n"));
  } catch (const InputError& e) {
    throw failed(e.what());
  } catch (const std::filesystem::filesystem_error& e) {
    throw failed(e.what());
  } catch (...) {
    std::filesystem::remove_all(built, error);
    throw;
  }
  try {
    const bool replaced = move_into_place(built, path);
    sync_directory(path.parent_path());
    if (replaced) std::filesystem::remove_all(built, error);
  } catch (...) {
    std::filesystem::remove_all(built, error);
    throw;
  }
}

}  // namespace psq::reports
