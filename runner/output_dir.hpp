#pragma once
#include <filesystem>

namespace psq::runner {

/// Creates the output directory (and parents) and checks that it is writable before any
/// long computation starts. Throws InputError naming the directory otherwise.
std::filesystem::path prepare_output_dir(const std::filesystem::path& dir);

}  // namespace psq::runner
