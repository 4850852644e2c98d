#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <numeric>
#include <set>

#include "engine/core/error.hpp"
#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/hierarchy/shell_prolongation.hpp"
#include "engine/hierarchy/triangle_quality.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_io.hpp"
#include "engine/mesh/topology.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

struct NamedMesh {
  std::string name;
  TriMesh mesh;
};

/// The four curved, unstructured meshes of the brief, each with a 3-level hierarchy.
const std::vector<std::pair<NamedMesh, MeshHierarchy>>& test_hierarchies() {
  static const auto hierarchies = [] {
    std::vector<NamedMesh> meshes{
        {"sphere", make_sphere({.radius = 0.5, .edge_length = 0.08})},
        {"cylinder", make_cylinder({.radius = 0.3, .height = 1.0, .edge_length = 0.07})},
        {"sheet with holes",
         make_sheet({.width = 1.0,
                     .height = 1.0,
                     .edge_length = 0.06,
                     .holes = {{-0.2, 0.1, 0.12}, {0.25, -0.2, 0.1}}})},
        {"bunny", read_mesh(test::shared_dir() / "data/meshes/bunny.obj")},
    };
    std::vector<std::pair<NamedMesh, MeshHierarchy>> result;
    for (auto& m : meshes) {
      MeshHierarchy h = build_hierarchy(m.mesh, {}, {.levels = 3, .vertex_ratio = 0.25});
      result.emplace_back(std::move(m), std::move(h));
    }
    return result;
  }();
  return hierarchies;
}

double relative_max_error(const Positions& a, const Positions& b) {
  return (a - b).rowwise().norm().maxCoeff() / bounding_box_diagonal(b);
}

TEST(BuildHierarchy, DirectProlongationRecoversTheFinestRestShapeAtEveryLevel) {
  for (const auto& [named, h] : test_hierarchies()) {
    ASSERT_EQ(h.level_count(), 3) << named.name;
    for (int l = 0; l < h.level_count(); ++l) {
      const ShellProlongation p = direct_prolongation(h, l);
      EXPECT_LT(relative_max_error(p.apply(h.levels[l].rest.vertices), named.mesh.vertices), 1e-10)
          << named.name << " level " << l;
    }
  }
}

TEST(BuildHierarchy, LevelProlongationRecoversTheNextFinerRestShape) {
  for (const auto& [named, h] : test_hierarchies()) {
    for (int l = 0; l + 1 < h.level_count(); ++l) {
      const ShellProlongation p = level_prolongation(h, l);
      EXPECT_LT(relative_max_error(p.apply(h.levels[l].rest.vertices),
                                   h.levels[l + 1].rest.vertices),
                1e-10)
          << named.name << " level " << l;
    }
  }
}

TEST(BuildHierarchy, LevelCountsFollowTheRatio) {
  for (const auto& [named, h] : test_hierarchies()) {
    for (int l = 0; l + 1 < h.level_count(); ++l) {
      const double ratio = static_cast<double>(h.levels[l].rest.vertex_count()) /
                           h.levels[l + 1].rest.vertex_count();
      EXPECT_GT(ratio, 0.2) << named.name << " level " << l;
      EXPECT_LT(ratio, 0.4) << named.name << " level " << l;
    }
  }
}

TEST(BuildHierarchy, EveryLevelKeepsTheAngleBound) {
  for (const auto& [named, h] : test_hierarchies()) {
    const double bound =
        std::min(kHierarchyMinAngleDegrees, mesh_quality(named.mesh).min_angle_degrees);
    for (int l = 0; l < h.level_count(); ++l) {
      const MeshQuality q = mesh_quality(h.levels[l].rest);
      EXPECT_GE(q.min_angle_degrees, bound) << named.name << " level " << l;
      // The angle bound implies this aspect-ratio bound (triangle_quality.hpp).
      EXPECT_LE(q.max_aspect_ratio, std::sqrt(3.0) / std::tan(bound * std::numbers::pi / 180))
          << named.name << " level " << l;
    }
  }
}

TEST(BuildHierarchy, NoTriangleFacesAwayFromTheFinestSurfaceItCovers) {
  for (const auto& [named, h] : test_hierarchies()) {
    const Positions finest_normals = vertex_normals(named.mesh);
    for (int l = 0; l < h.level_count(); ++l) {
      const TriMesh& rest = h.levels[l].rest;
      for (int i = 0; i < named.mesh.vertex_count(); ++i) {
        const auto tri = rest.triangles.row(h.levels[l].finest[i].triangle);
        const Eigen::Vector3d a = rest.vertices.row(tri(0));
        const Eigen::Vector3d n = (Eigen::Vector3d(rest.vertices.row(tri(1))) - a)
                                      .cross(Eigen::Vector3d(rest.vertices.row(tri(2))) - a);
        ASSERT_GT(n.dot(finest_normals.row(i)), 0)
            << named.name << " level " << l << " vertex " << i;
      }
    }
  }
}

TEST(BuildHierarchy, BoundaryLoopsArePreservedAndBoundaryVerticesNeverMove) {
  for (const auto& [named, h] : test_hierarchies()) {
    const MeshTopology finest = MeshTopology::build(named.mesh);
    std::set<std::array<double, 3>> finest_boundary;
    for (const auto& loop : finest.boundary_loops) {
      for (const int v : loop) {
        finest_boundary.insert({named.mesh.vertices(v, 0), named.mesh.vertices(v, 1),
                                named.mesh.vertices(v, 2)});
      }
    }
    for (int l = 0; l < h.level_count(); ++l) {
      const TriMesh& rest = h.levels[l].rest;
      const MeshTopology topology = MeshTopology::build(rest);
      EXPECT_EQ(topology.boundary_loops.size(), finest.boundary_loops.size())
          << named.name << " level " << l;
      for (const auto& loop : topology.boundary_loops) {
        EXPECT_GE(loop.size(), 3u);
        for (const int v : loop) {
          EXPECT_TRUE(finest_boundary.count({rest.vertices(v, 0), rest.vertices(v, 1),
                                             rest.vertices(v, 2)}))
              << named.name << " level " << l << " boundary vertex " << v << " moved";
        }
      }
    }
  }
}

TEST(BuildHierarchy, ParentsMapEveryFinerVertexOntoTheCoarserLevel) {
  for (const auto& [named, h] : test_hierarchies()) {
    for (int l = 0; l + 1 < h.level_count(); ++l) {
      const HierarchyLevel& coarse = h.levels[l];
      ASSERT_EQ(static_cast<int>(coarse.parent.size()), h.levels[l + 1].rest.vertex_count());
      std::vector<int> children(coarse.rest.vertex_count(), 0);
      for (const int p : coarse.parent) {
        ASSERT_GE(p, 0);
        ASSERT_LT(p, coarse.rest.vertex_count());
        ++children[p];
      }
      // Every coarse vertex is the survivor of at least one finer vertex.
      EXPECT_GT(*std::min_element(children.begin(), children.end()), 0) << named.name;
    }
  }
}

TEST(BuildHierarchy, RecordedCollapsesReplayedGiveTheParents) {
  // Each collapse removes one finer vertex into a survivor; following the survivors to the end
  // must land on each vertex's parent, and the coarse vertices are the finer ones never removed.
  for (const auto& [named, h] : test_hierarchies()) {
    for (int l = 0; l + 1 < h.level_count(); ++l) {
      const HierarchyLevel& coarse = h.levels[l];
      const int finer = h.levels[l + 1].rest.vertex_count();
      ASSERT_EQ(static_cast<int>(coarse.collapses.size()), finer - coarse.rest.vertex_count());
      std::vector<int> merged_into(finer, -1);
      for (const auto& [removed, survivor] : coarse.collapses) {
        ASSERT_EQ(merged_into[removed], -1) << named.name << ": vertex removed twice";
        ASSERT_EQ(merged_into[survivor], -1) << named.name << ": survivor already removed";
        merged_into[removed] = survivor;
      }
      std::vector<int> root_of_parent(coarse.rest.vertex_count(), -1);
      for (int v = 0; v < finer; ++v) {
        int root = v;
        while (merged_into[root] >= 0) root = merged_into[root];
        // One root per coarse vertex: the finer vertex that survived into it.
        int& recorded = root_of_parent[coarse.parent[v]];
        if (recorded < 0) recorded = root;
        EXPECT_EQ(recorded, root) << named.name << " level " << l << " vertex " << v;
      }
    }
  }
}

TEST(BuildHierarchy, ExpansionsOfOneColourTouchNoCommonFinerTriangle) {
  for (const auto& [named, h] : test_hierarchies()) {
    for (int l = 0; l + 1 < h.level_count(); ++l) {
      const HierarchyLevel& coarse = h.levels[l];
      ASSERT_EQ(static_cast<int>(coarse.expansion_color.size()), coarse.rest.vertex_count());
      const Triangles& finer = h.levels[l + 1].rest.triangles;
      for (int t = 0; t < finer.rows(); ++t) {
        for (int a = 0; a < 3; ++a) {
          for (int b = a + 1; b < 3; ++b) {
            const int pa = coarse.parent[finer(t, a)], pb = coarse.parent[finer(t, b)];
            if (pa != pb) {
              EXPECT_NE(coarse.expansion_color[pa], coarse.expansion_color[pb]) << named.name;
            }
          }
        }
      }
      // Greedy colouring of a surface conflict graph needs only a handful of colours.
      EXPECT_LT(*std::max_element(coarse.expansion_color.begin(), coarse.expansion_color.end()),
                32);
    }
  }
}

TEST(BuildHierarchy, ProlongationCommutesWithRigidMotions) {
  const auto& [named, h] = test_hierarchies()[3];  // the bunny
  const ShellProlongation p = direct_prolongation(h, 0);
  const Positions& rest = h.levels[0].rest.vertices;
  const Positions x = rest + 0.02 * bounding_box_diagonal(rest) *
                                 Positions::Random(rest.rows(), 3);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  const Eigen::RowVector3d translation(-2.0, 0.5, 3.0);
  const Positions moved = (x * rotation.transpose()).rowwise() + translation;
  const Positions expected = (p.apply(x) * rotation.transpose()).rowwise() + translation;
  EXPECT_LT(relative_max_error(p.apply(moved), expected), 1e-12);
}

TEST(BuildHierarchy, RejectsBadSettings) {
  const TriMesh sheet = make_sheet({.edge_length = 0.2, .holes = {}, .structured = true});
  EXPECT_THROW(build_hierarchy(sheet, {}, {.levels = 0}), InputError);
  EXPECT_THROW(build_hierarchy(sheet, {}, {.levels = 2, .vertex_ratio = 1.0}), InputError);
  EXPECT_THROW(build_hierarchy(sheet, {}, {.levels = 2, .vertex_ratio = 0.0}), InputError);
  EXPECT_THROW(build_hierarchy(sheet, std::vector<int>(3, kFreeVertex), {}), InputError);
  try {
    // Every vertex in its own pinned set: no collapse is allowed at all.
    std::vector<int> pins(sheet.vertex_count());
    std::iota(pins.begin(), pins.end(), 0);
    build_hierarchy(sheet, pins, {.levels = 2});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("level 0"), std::string::npos) << e.what();
  }
}

TEST(BuildHierarchy, AllowingFewerLevelsEndsTheHierarchyWhereNoCollapseIsLeft) {
  // Every vertex its own pinned set: level 0 cannot be made, so with fewer levels allowed the
  // hierarchy is the input mesh alone instead of an error; a mesh that decimates twice but not
  // three times ends after its reachable levels.
  const TriMesh sheet = make_sheet({.edge_length = 0.2, .holes = {}, .structured = true});
  std::vector<int> pins(sheet.vertex_count());
  std::iota(pins.begin(), pins.end(), 0);
  const MeshHierarchy alone =
      build_hierarchy(sheet, pins, {.levels = 3, .allow_fewer_levels = true});
  ASSERT_EQ(alone.level_count(), 1);
  EXPECT_EQ(alone.finest().rest.vertices, sheet.vertices);
  const TriMesh square = make_sheet({.edge_length = 0.5, .holes = {}, .structured = true});
  const MeshHierarchy deep =
      build_hierarchy(square, {}, {.levels = 12, .allow_fewer_levels = true});
  EXPECT_GT(deep.level_count(), 1);
  EXPECT_LT(deep.level_count(), 12);
  for (int l = 0; l + 1 < deep.level_count(); ++l)
    EXPECT_LT(deep.levels[l].rest.vertex_count(), deep.levels[l + 1].rest.vertex_count());
  EXPECT_THROW(build_hierarchy(square, {}, {.levels = 12}), InputError);
}

TEST(BuildHierarchy, OneLevelIsTheInputMesh) {
  const TriMesh sheet = make_sheet({.edge_length = 0.2, .holes = {}, .structured = true});
  const MeshHierarchy h = build_hierarchy(sheet, {}, {.levels = 1});
  ASSERT_EQ(h.level_count(), 1);
  EXPECT_EQ(h.finest().rest.vertices, sheet.vertices);
  EXPECT_EQ(h.finest().rest.triangles, sheet.triangles);
}

}  // namespace
}  // namespace psq
