#include "progressive/nested_cases.hpp"

#include <stdexcept>

#include "engine/scene/scene_reader.hpp"
#include "engine/sim/shell_system.hpp"
#include "support/test_paths.hpp"

namespace psq::test {
namespace {

/// Coarse grids of 40–130 vertices (fine: 4× as many), matching each scene's proportions.
GridSpec coarse_grid(const std::string& name) {
  if (name == "drape") return {8, 8, false, sheet_shape(1.0, 1.0)};
  if (name == "twist") return {12, 3, false, sheet_shape(0.4, 0.1)};
  if (name == "cylinder_compress") return {16, 4, true, cylinder_shape(0.05, 0.1)};
  throw std::invalid_argument("nested_case: no grid for scene " + name);
}

}  // namespace

NestedCase nested_case(const std::string& name, int frames) {
  NestedCase out;
  out.scene = read_scene(source_dir() / "jobs" / "scenes" / (name + ".toml"));
  out.scene.time.step *= double(out.scene.time.frames) / frames;
  out.scene.time.frames = frames;
  const GridSpec coarse = coarse_grid(name);
  use_mesh_file(out.scene, grid_mesh(refined(coarse)), fresh_temp_dir("nested_" + name), name);
  const ShellSystem fine(out.scene);
  out.hierarchy = nested_hierarchy(coarse, fine.pin_groups(0));
  return out;
}

}  // namespace psq::test
