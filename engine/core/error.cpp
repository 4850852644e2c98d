#include "engine/core/error.hpp"

#include <fmt/format.h>

namespace psq {

std::string located_message(const std::string& file, long line, const std::string& message) {
  if (line > 0) return fmt::format("{}:{}: {}", file, line, message);
  return fmt::format("{}: {}", file, message);
}

}  // namespace psq
