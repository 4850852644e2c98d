#pragma once
#include <vector>

#include "engine/contact/intersection_check.hpp"
#include "engine/sim/shell_system.hpp"

namespace psq::runner {

/// The shells of a system as named triangle ranges, so that reports say "shell 'cloth'
/// triangle 12" instead of a global index.
std::vector<TrianglePart> shell_parts(const ShellSystem& system);

}  // namespace psq::runner
