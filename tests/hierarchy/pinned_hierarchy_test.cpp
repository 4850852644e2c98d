#include <gtest/gtest.h>

#include <map>

#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/hierarchy/shell_prolongation.hpp"
#include "engine/mesh/generators.hpp"

namespace psq {
namespace {

/// A sheet clamped along its left edge (set 0) and right edge (set 1), as in a twist scene.
struct ClampedSheet {
  TriMesh mesh;
  std::vector<int> pins;
};

ClampedSheet clamped_sheet() {
  ClampedSheet s;
  s.mesh = make_sheet({.width = 1.0, .height = 0.6, .edge_length = 0.04, .holes = {}});
  s.pins.assign(s.mesh.vertex_count(), kFreeVertex);
  for (int v = 0; v < s.mesh.vertex_count(); ++v) {
    if (s.mesh.vertices(v, 0) < -0.5 + 1e-9) s.pins[v] = 0;
    if (s.mesh.vertices(v, 0) > 0.5 - 1e-9) s.pins[v] = 1;
  }
  return s;
}

TEST(PinnedHierarchy, PinnedVerticesKeepTheirSetAndFinestPositionAtEveryLevel) {
  const ClampedSheet s = clamped_sheet();
  const MeshHierarchy h = build_hierarchy(s.mesh, s.pins, {.levels = 3, .vertex_ratio = 0.25});
  ASSERT_EQ(h.level_count(), 3);
  std::map<std::array<double, 3>, int> finest_pinned;
  for (int v = 0; v < s.mesh.vertex_count(); ++v) {
    if (s.pins[v] != kFreeVertex) {
      finest_pinned[{s.mesh.vertices(v, 0), s.mesh.vertices(v, 1), s.mesh.vertices(v, 2)}] =
          s.pins[v];
    }
  }
  EXPECT_EQ(h.finest().pin_group, s.pins);
  for (int l = 0; l < h.level_count(); ++l) {
    const HierarchyLevel& level = h.levels[l];
    ASSERT_EQ(static_cast<int>(level.pin_group.size()), level.rest.vertex_count());
    int pinned[2] = {0, 0};
    for (int v = 0; v < level.rest.vertex_count(); ++v) {
      if (level.pin_group[v] == kFreeVertex) continue;
      const auto it = finest_pinned.find(
          {level.rest.vertices(v, 0), level.rest.vertices(v, 1), level.rest.vertices(v, 2)});
      ASSERT_NE(it, finest_pinned.end()) << "level " << l << " pinned vertex " << v << " moved";
      EXPECT_EQ(it->second, level.pin_group[v]);
      ++pinned[level.pin_group[v]];
    }
    // Both clamps survive on every level (their end corners can never be removed).
    EXPECT_GE(pinned[0], 2) << "level " << l;
    EXPECT_GE(pinned[1], 2) << "level " << l;
  }
  for (int l = 0; l + 1 < h.level_count(); ++l) {
    EXPECT_LT(h.levels[l].rest.vertex_count(), h.levels[l + 1].rest.vertex_count());
  }
}

TEST(PinnedHierarchy, RigidlyMovedClampsProlongToTheSameMotionOfTheFinestClamps) {
  // Translating the whole coarse level moves every finest vertex by the same amount, so the
  // Dirichlet data of the finest level and of every coarse level agree.
  const ClampedSheet s = clamped_sheet();
  const MeshHierarchy h = build_hierarchy(s.mesh, s.pins, {.levels = 3, .vertex_ratio = 0.25});
  const Eigen::RowVector3d shift(0.1, -0.3, 0.7);
  for (int l = 0; l < h.level_count(); ++l) {
    const ShellProlongation p = direct_prolongation(h, l);
    const Positions moved = h.levels[l].rest.vertices.rowwise() + shift;
    const Positions fine = p.apply(moved);
    EXPECT_LT((fine - (s.mesh.vertices.rowwise() + shift)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

}  // namespace
}  // namespace psq
