#pragma once
// The scene library's drape, twist and cylinder scenes at CI size: the mesh replaced by the
// refinement of a small structured grid, with the two-level nested hierarchy over it.

#include <string>

#include "engine/scene/scene.hpp"
#include "progressive/nested_grids.hpp"

namespace psq::test {

struct NestedCase {
  Scene scene;
  MeshHierarchy hierarchy;
};

/// "drape", "twist" or "cylinder_compress" from jobs/scenes with its loading time spread over
/// `frames` frames and its shell's mesh replaced by the fine grid of a nested pair.
NestedCase nested_case(const std::string& name, int frames);

}  // namespace psq::test
