#pragma once
// Files that are either absent, the previous version, or complete: written to a temporary
// name in the same directory, flushed to disk, then renamed over the target.

#include <filesystem>
#include <functional>
#include <ostream>

namespace psq {

/// Calls `write` on a stream to a temporary file beside `path`, then fsyncs and renames it to
/// `path`. Throws InputError naming the path if it cannot be written (the temporary is removed).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace psq
