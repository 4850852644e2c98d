#pragma once
#include <filesystem>
#include <string>

namespace psq::test {

std::filesystem::path source_dir();  ///< the repository root
std::filesystem::path shared_dir();  ///< ../shared beside the repository (paper, data)
/// A new empty directory under the build tree, unique to this test and call.
std::filesystem::path fresh_temp_dir(const std::string& name);
/// Writes text to a file and returns its path.
std::filesystem::path write_file(const std::filesystem::path& path, const std::string& text);
/// The bytes of a file, read whole (empty if it cannot be opened).
std::string read_file(const std::filesystem::path& path);

}  // namespace psq::test
