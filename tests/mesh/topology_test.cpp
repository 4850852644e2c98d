#include <gtest/gtest.h>

#include <set>

#include "engine/core/error.hpp"
#include "engine/mesh/topology.hpp"

namespace psq {
namespace {

// Two triangles sharing the diagonal of the unit square.
TriMesh unit_square() {
  TriMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.triangles.resize(2, 3);
  m.triangles << 0, 1, 2, 0, 2, 3;
  return m;
}

TEST(Topology, SquareHasOneHingeAndOneBoundaryLoop) {
  const TriMesh m = unit_square();
  const MeshTopology t = MeshTopology::build(m);
  EXPECT_EQ(t.edges.size(), 5u);
  ASSERT_EQ(t.hinges.size(), 1u);
  const Hinge& h = t.hinges[0];
  EXPECT_EQ(std::set<int>({h.v0, h.v1}), std::set<int>({0, 2}));
  EXPECT_EQ(std::set<int>({h.opposite0, h.opposite1}), std::set<int>({1, 3}));
  ASSERT_EQ(t.boundary_loops.size(), 1u);
  EXPECT_EQ(t.boundary_loops[0], (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(t.vertex_neighbors[0], (std::vector<int>{1, 2, 3}));
}

TEST(Topology, HingeOrientationFollowsFaces) {
  const TriMesh m = unit_square();
  const Hinge h = MeshTopology::build(m).hinges[0];
  auto has_directed = [&](int f, int a, int b, int c) {
    for (int k = 0; k < 3; ++k)
      if (m.triangles(f, k) == a && m.triangles(f, (k + 1) % 3) == b && m.triangles(f, (k + 2) % 3) == c)
        return true;
    return false;
  };
  EXPECT_TRUE(has_directed(h.face0, h.v0, h.v1, h.opposite0));
  EXPECT_TRUE(has_directed(h.face1, h.v1, h.v0, h.opposite1));
}

TEST(Topology, NonManifoldEdgeIsRejected) {
  TriMesh m = unit_square();
  m.vertices.conservativeResize(5, 3);
  m.vertices.row(4) << 0.5, 0.5, 1;
  m.triangles.conservativeResize(3, 3);
  m.triangles.row(2) << 2, 0, 4;
  EXPECT_THROW(
      {
        try {
          MeshTopology::build(m, "three.obj");
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("three.obj"), std::string::npos);
          EXPECT_NE(std::string(e.what()).find("non-manifold"), std::string::npos);
          throw;
        }
      },
      InputError);
}

TEST(Topology, InconsistentOrientationIsRejected) {
  TriMesh m = unit_square();
  m.triangles.row(1) << 0, 3, 2;
  EXPECT_THROW(MeshTopology::build(m), InputError);
}

}  // namespace
}  // namespace psq
