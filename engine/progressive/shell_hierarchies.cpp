#include <fmt/format.h>

#include "engine/core/error.hpp"
#include "engine/hierarchy/hierarchy_cache.hpp"
#include "engine/progressive/progressive_simulation.hpp"

namespace psq {
namespace {

/// Shell `s` of the concatenated rest mesh, in the shell's own vertex numbering.
TriMesh shell_rest_mesh(const ShellSystem& system, int s) {
  const ShellBlock& block = system.shells()[s];
  TriMesh mesh;
  mesh.vertices = system.rest_mesh().vertices.middleRows(block.first_vertex, block.vertex_count);
  mesh.triangles =
      system.rest_mesh().triangles.middleRows(block.first_triangle, block.triangle_count).array() -
      block.first_vertex;
  return mesh;
}

}  // namespace

std::vector<MeshHierarchy> build_shell_hierarchies(const ShellSystem& finest,
                                                   const ProgressiveSettings& settings) {
  HierarchySettings hierarchy;
  hierarchy.levels = settings.schedule.levels;
  hierarchy.vertex_ratio = settings.schedule.vertex_ratio;
  std::vector<MeshHierarchy> out;
  for (int s = 0; s < static_cast<int>(finest.shells().size()); ++s) {
    const TriMesh mesh = shell_rest_mesh(finest, s);
    out.push_back(settings.cache_dir.empty()
                      ? build_hierarchy(mesh, finest.pin_groups(s), hierarchy)
                      : load_or_build_hierarchy(mesh, finest.pin_groups(s), hierarchy,
                                                settings.cache_dir));
  }
  return out;
}

}  // namespace psq
