#include <chrono>

#include "engine/hierarchy/hierarchy_cache.hpp"
#include "engine/progressive/progressive_simulation.hpp"

namespace psq {
namespace {

/// load_or_build_hierarchy, timed, its cache use appended to `uses` when given.
MeshHierarchy load_or_build_timed(const TriMesh& mesh, const std::vector<int>& pin_group,
                                  const HierarchySettings& rules,
                                  const std::filesystem::path& cache_dir,
                                  std::vector<HierarchyCacheUse>* uses) {
  const auto start = std::chrono::steady_clock::now();
  HierarchyCacheUse use;
  use.key = hierarchy_cache_key(mesh, pin_group, rules);
  MeshHierarchy hierarchy = load_or_build_hierarchy(mesh, pin_group, rules, cache_dir, &use.outcome);
  use.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (uses) uses->push_back(use);
  return hierarchy;
}

}  // namespace

std::vector<MeshHierarchy> build_hierarchies(const ShellSystem& finest,
                                             const ProgressiveSettings& settings,
                                             std::vector<HierarchyCacheUse>* uses) {
  HierarchySettings hierarchy;
  hierarchy.levels = settings.schedule.levels;
  hierarchy.vertex_ratio = settings.schedule.vertex_ratio;
  const auto build = [&](const TriMesh& mesh, const std::vector<int>& pin_group,
                         const HierarchySettings& rules) {
    return settings.cache_dir.empty()
               ? build_hierarchy(mesh, pin_group, rules)
               : load_or_build_timed(mesh, pin_group, rules, settings.cache_dir, uses);
  };
  std::vector<MeshHierarchy> out;
  for (int s = 0; s < static_cast<int>(finest.shells().size()); ++s)
    out.push_back(build(finest.shell_rest_mesh(s), finest.pin_groups(s), hierarchy));
  // All of a collider's vertices as one pinned set: every collapse then keeps its survivor
  // where it is, so each coarse vertex is a vertex of the collider's own surface (one rigid
  // motion places every level alike) and a convex part decimates inward, under a shell resting
  // on it, instead of to the quadric's optimum outside the surface.
  HierarchySettings collider = hierarchy;
  collider.allow_fewer_levels = true;
  for (int c = 0; c < static_cast<int>(finest.colliders().size()); ++c)
    out.push_back(build(finest.collider_rest_mesh(c),
                        std::vector<int>(finest.colliders()[c].vertex_count, 0), collider));
  return out;
}

}  // namespace psq
