#include "engine/core/input_file.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

#include "engine/core/error.hpp"

namespace psq {

std::string read_input_file(const std::filesystem::path& path, std::string_view what) {
  const std::string file = path.string();
  const auto fail = [&](const std::string& message) {
    throw InputError(located_message(file, 0, message));
  };
  std::error_code error;
  if (!std::filesystem::exists(path, error)) fail(fmt::format("no such {}", what));
  if (!std::filesystem::is_regular_file(path, error))
    fail(fmt::format("the {} is not a regular file", what));
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(fmt::format("cannot open the {}: {}", what, std::strerror(errno)));
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) fail(fmt::format("read error in the {}", what));
  return bytes;
}

}  // namespace psq
