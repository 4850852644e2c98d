#include "runner/output_dir.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include "engine/core/error.hpp"

namespace psq::runner {

std::filesystem::path prepare_output_dir(const std::filesystem::path& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error)
    throw InputError(fmt::format("cannot create output directory '{}': {}", dir.string(), error.message()));
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(fmt::format("output directory '{}' is not writable", dir.string()));
  return dir;
}

}  // namespace psq::runner
