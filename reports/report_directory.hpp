#pragma once
// A report directory that appears whole or not at all: it is built in a temporary directory
// beside the target and then renamed into place.

#include <filesystem>
#include <functional>

namespace psq::reports {

/// Name of the marker file that identifies a directory written by publish_directory: only
/// such a directory (or an empty one) is ever replaced.
inline constexpr const char* kReportMarker = ".psq-report";

/// Creates `target`'s parent directories if needed, builds a new directory `.NAME.tmpPID`
/// beside `target`, calls `fill` with it, adds the marker file, and puts it in place of
/// `target`: renamed, or atomically exchanged (renameat2 RENAME_EXCHANGE) with an existing
/// report, whose old content is then removed. If anything fails — including `fill` — the
/// temporary directory is removed and `target` is left as it was. Throws InputError naming
/// `target` if it exists but is not a directory, is a non-empty directory without the marker,
/// or cannot be written, and for an InputError or file system error from `fill` (its message
/// inside); other exceptions from `fill` propagate.
void publish_directory(const std::filesystem::path& target,
                       const std::function<void(const std::filesystem::path&)>& fill);

}  // namespace psq::reports
