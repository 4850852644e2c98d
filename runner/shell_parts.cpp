#include "runner/shell_parts.hpp"

#include <fmt/format.h>

namespace psq::runner {

std::vector<TrianglePart> shell_parts(const ShellSystem& system) {
  std::vector<TrianglePart> parts;
  for (const ShellBlock& shell : system.shells())
    parts.push_back({fmt::format("shell '{}'", shell.name), shell.first_triangle, shell.triangle_count});
  return parts;
}

}  // namespace psq::runner
