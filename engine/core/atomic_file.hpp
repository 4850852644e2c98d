#pragma once
// Files that are either absent, the previous version, or complete: written to a temporary
// name in the same directory, flushed to disk, then renamed over the target.

#include <filesystem>
#include <functional>
#include <ostream>

namespace psq {

/// Calls `produce` with a temporary path beside `path` for it to create the file there (any
/// library that writes by file name, e.g. HDF5), then fsyncs it, renames it to `path` and
/// fsyncs the directory. Throws InputError naming `path` if a step fails; exceptions from
/// `produce` propagate. Either way the temporary is removed and `path` is left as it was.
void replace_file_atomically(const std::filesystem::path& path,
                             const std::function<void(const std::filesystem::path&)>& produce);

/// replace_file_atomically for content written to a stream.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace psq
