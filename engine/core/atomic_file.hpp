#pragma once
// Files that are either absent, the previous version, or complete: written to a temporary
// name in the same directory, flushed to disk, then renamed over the target.

#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>

namespace psq {

/// Calls `produce` with a temporary path beside `path` for it to create the file there (any
/// library that writes by file name, e.g. HDF5), then fsyncs it, renames it to `path` and
/// fsyncs the directory. Throws InputError naming `path` if a step fails; exceptions from
/// `produce` propagate. Either way the temporary is removed and `path` is left as it was.
void replace_file_atomically(const std::filesystem::path& path,
                             const std::function<void(const std::filesystem::path&)>& produce);

/// replace_file_atomically for bytes in memory. The InputError of a failed write names `path`
/// and the system's reason ("No space left on device", "Read-only file system", ...).
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

/// write_file_atomically for content written to a stream (collected in memory, then written as
/// above).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace psq
