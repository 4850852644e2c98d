#include "engine/hierarchy/hierarchy_cache.hpp"
#include "engine/progressive/progressive_simulation.hpp"

namespace psq {

std::vector<MeshHierarchy> build_shell_hierarchies(const ShellSystem& finest,
                                                   const ProgressiveSettings& settings) {
  HierarchySettings hierarchy;
  hierarchy.levels = settings.schedule.levels;
  hierarchy.vertex_ratio = settings.schedule.vertex_ratio;
  std::vector<MeshHierarchy> out;
  for (int s = 0; s < static_cast<int>(finest.shells().size()); ++s) {
    const TriMesh mesh = finest.shell_rest_mesh(s);
    out.push_back(
        settings.cache_dir.empty()
            ? build_hierarchy(mesh, finest.pin_groups(s), hierarchy)
            : load_or_build_hierarchy(mesh, finest.pin_groups(s), hierarchy, settings.cache_dir));
  }
  return out;
}

}  // namespace psq
