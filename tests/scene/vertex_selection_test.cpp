#include "engine/scene/vertex_selection.hpp"

#include <gtest/gtest.h>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"

namespace psq {
namespace {

/// 1 m × 0.5 m structured sheet with 0.1 m edges: 10 × 5 squares, vertices at
/// x = -0.5 + 0.1 i (i = 0..10) and y = -0.25 + 0.1 j (j = 0..5).
TriMesh grid_sheet() {
  SheetGenerator spec;
  spec.width = 1.0;
  spec.height = 0.5;
  spec.edge_length = 0.1;
  spec.structured = true;
  return make_structured_sheet(spec);
}

VertexSelector box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  VertexSelector s;
  s.kind = VertexSelector::Kind::Box;
  s.box_min = lo;
  s.box_max = hi;
  return s;
}

class SelectOnGrid : public ::testing::Test {
 protected:
  TriMesh mesh = grid_sheet();
  MeshTopology topology = MeshTopology::build(mesh);
};

TEST_F(SelectOnGrid, BoxCountsMatchTheGrid) {
  ASSERT_EQ(mesh.vertex_count(), 11 * 6);
  // Interior box: |x| ≤ 0.25 holds i = 3..7 (5 columns), |y| ≤ 0.3 holds all 6 rows.
  EXPECT_EQ(select_vertices(box({-0.25, -0.3, -1}, {0.25, 0.3, 1}), mesh, topology, "b").size(),
            5u * 6u);
  // Faces exactly on grid lines: x ∈ [-0.3, 0.3] holds i = 2..8 (7), y ∈ [-0.15, 0.15] holds
  // j = 1..4 (4). The vertex coordinates carry round-off; the selection must not.
  EXPECT_EQ(select_vertices(box({-0.3, -0.15, 0}, {0.3, 0.15, 0}), mesh, topology, "b").size(),
            7u * 4u);
  // A flat box on the left edge x = -0.5: one column of 6 vertices.
  EXPECT_EQ(select_vertices(box({-0.5, -1, 0}, {-0.5, 1, 0}), mesh, topology, "b").size(), 6u);
  // Everything.
  EXPECT_EQ(select_vertices(box({-1, -1, -1}, {1, 1, 1}), mesh, topology, "b").size(), 66u);
}

TEST_F(SelectOnGrid, BoxSelectsExactlyTheVerticesInside) {
  const Eigen::Vector3d lo(0.05, -0.1, -1), hi(0.35, 0.3, 1);
  const std::vector<int> selected = select_vertices(box(lo, hi), mesh, topology, "b");
  ASSERT_TRUE(std::is_sorted(selected.begin(), selected.end()));
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector3d p = mesh.vertices.row(v);
    const bool inside = (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
    EXPECT_EQ(inside, std::binary_search(selected.begin(), selected.end(), v)) << v;
  }
  EXPECT_EQ(selected.size(), 3u * 4u);  // x = 0.1, 0.2, 0.3; y = -0.05, 0.05, 0.15, 0.25
}

TEST_F(SelectOnGrid, EmptyBoxIsAnErrorNamingTheSelectorAndItsLine) {
  VertexSelector s = box({2, 2, 2}, {3, 3, 3});
  s.source_file = "scene.toml";
  s.source_line = 14;
  try {
    select_vertices(s, mesh, topology, "pin 'left' of shell 'sheet'");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("scene.toml:14:"), std::string::npos) << message;
    EXPECT_NE(message.find("pin 'left' of shell 'sheet' selects no vertex"), std::string::npos)
        << message;
    EXPECT_NE(message.find("box [2, 2, 2]..[3, 3, 3]"), std::string::npos) << message;
  }
}

TEST_F(SelectOnGrid, BoundaryLoopOfASheetIsItsRim) {
  VertexSelector s;
  s.kind = VertexSelector::Kind::BoundaryLoop;
  s.boundary_loop = 0;
  const std::vector<int> rim = select_vertices(s, mesh, topology, "rim");
  EXPECT_EQ(rim.size(), 2u * (10u + 5u));
  for (int v : rim) {
    const Eigen::Vector3d p = mesh.vertices.row(v);
    EXPECT_TRUE(std::abs(std::abs(p.x()) - 0.5) < 1e-12 || std::abs(std::abs(p.y()) - 0.25) < 1e-12)
        << v;
  }
  s.boundary_loop = 1;
  EXPECT_THROW(select_vertices(s, mesh, topology, "rim"), InputError);
}

TEST_F(SelectOnGrid, ListIsSortedAndDeduplicated) {
  VertexSelector s;
  s.kind = VertexSelector::Kind::List;
  s.indices = {65, 3, 0, 3};
  EXPECT_EQ(select_vertices(s, mesh, topology, "list"), (std::vector<int>{0, 3, 65}));
}

TEST_F(SelectOnGrid, OutOfRangeIndexIsAnErrorNamingIt) {
  VertexSelector s;
  s.kind = VertexSelector::Kind::List;
  s.indices = {0, 66};
  try {
    select_vertices(s, mesh, topology, "load 1 of shell 'sheet'");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("load 1 of shell 'sheet'"), std::string::npos) << message;
    EXPECT_NE(message.find("vertex 66"), std::string::npos) << message;
  }
}

/// Two separate sheets: a single square (vertices 0..3, rim of 4) and then a 3 × 3 grid
/// (vertices 4..19, rim of 12). The topology finds the small rim first (it holds vertex 0).
TriMesh small_then_large_sheet() {
  SheetGenerator small_spec;
  small_spec.width = small_spec.height = small_spec.edge_length = 1.0;
  small_spec.structured = true;
  SheetGenerator large_spec = small_spec;
  large_spec.width = large_spec.height = 3.0;
  const TriMesh small = make_structured_sheet(small_spec);
  const TriMesh large = make_structured_sheet(large_spec);
  TriMesh both;
  both.vertices.resize(small.vertex_count() + large.vertex_count(), 3);
  both.vertices << small.vertices, large.vertices.rowwise() + Eigen::RowVector3d(10, 0, 0);
  both.triangles.resize(small.triangle_count() + large.triangle_count(), 3);
  both.triangles << small.triangles, (large.triangles.array() + small.vertex_count()).matrix();
  return both;
}

TEST(SelectBoundaryLoop, LoopsAreNumberedLargestFirst) {
  const TriMesh mesh = small_then_large_sheet();
  const MeshTopology topology = MeshTopology::build(mesh);
  ASSERT_EQ(topology.boundary_loops.size(), 2u);
  ASSERT_EQ(topology.boundary_loops[0].size(), 4u);  // the premise: small loop found first

  VertexSelector s;
  s.kind = VertexSelector::Kind::BoundaryLoop;
  s.boundary_loop = 0;
  const std::vector<int> large = select_vertices(s, mesh, topology, "loop 0");
  EXPECT_EQ(large.size(), 12u);
  EXPECT_GE(large.front(), 4);
  s.boundary_loop = 1;
  EXPECT_EQ(select_vertices(s, mesh, topology, "loop 1"), (std::vector<int>{0, 1, 2, 3}));
  s.boundary_loop = 2;
  EXPECT_THROW(select_vertices(s, mesh, topology, "loop 2"), InputError);
}

}  // namespace
}  // namespace psq
