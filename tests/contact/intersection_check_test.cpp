// Exact intersection check: hand-made pairs for every shared-vertex case, exact touching and
// near misses, and whole meshes with and without a vertex pushed through.

#include "engine/contact/intersection_check.hpp"

#include <gtest/gtest.h>

#include <set>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"

namespace psq {
namespace {

using Vector3 = Eigen::Vector3d;
using Pairs = std::vector<std::array<int, 2>>;

TriMesh mesh_of(const std::vector<Vector3>& points,
                const std::vector<std::array<int, 3>>& triangles) {
  TriMesh mesh;
  mesh.vertices.resize(static_cast<int>(points.size()), 3);
  for (std::size_t v = 0; v < points.size(); ++v) mesh.vertices.row(v) = points[v].transpose();
  mesh.triangles.resize(static_cast<int>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    mesh.triangles.row(t) << triangles[t][0], triangles[t][1], triangles[t][2];
  return mesh;
}

/// The unit right triangle in z = 0 (vertices 0, 1, 2) and a second triangle (vertices 3, 4, 5).
bool separate_triangles_intersect(const Vector3& a, const Vector3& b, const Vector3& c) {
  const TriMesh mesh = mesh_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, a, b, c}, {{0, 1, 2}, {3, 4, 5}});
  const IntersectionReport report = find_intersections(mesh.vertices, mesh.triangles);
  EXPECT_TRUE(report.degenerate_triangles.empty());
  return !report.intersecting_pairs.empty();
}

/// The unit right triangle (0, 1, 2) and the triangle (0, 3, 4) sharing its corner at the origin.
bool triangles_sharing_the_origin_intersect(const Vector3& p3, const Vector3& p4) {
  const TriMesh mesh = mesh_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, p3, p4}, {{0, 1, 2}, {0, 3, 4}});
  return !find_intersections(mesh.vertices, mesh.triangles).intersecting_pairs.empty();
}

/// The unit right triangle (0, 1, 2) and the triangle (2, 1, 3) across its long edge.
bool triangles_sharing_an_edge_intersect(const Vector3& p3) {
  const TriMesh mesh = mesh_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, p3}, {{0, 1, 2}, {2, 1, 3}});
  return !find_intersections(mesh.vertices, mesh.triangles).intersecting_pairs.empty();
}

TEST(IntersectionCheck, SeparateTriangles) {
  // One pierces the other.
  EXPECT_TRUE(separate_triangles_intersect({0.2, 0.2, -0.5}, {0.3, 0.2, 0.5}, {0.2, 0.3, 0.5}));
  // The same, lifted clear.
  EXPECT_FALSE(separate_triangles_intersect({0.2, 0.2, 0.5}, {0.3, 0.2, 1.5}, {0.2, 0.3, 1.5}));
  // A corner touching the interior exactly counts; 1e-12 above does not; 1e-12 below pierces.
  EXPECT_TRUE(separate_triangles_intersect({0.2, 0.2, 0}, {0.5, 0.2, 1}, {0.2, 0.5, 1}));
  EXPECT_FALSE(separate_triangles_intersect({0.2, 0.2, 1e-12}, {0.5, 0.2, 1}, {0.2, 0.5, 1}));
  EXPECT_TRUE(separate_triangles_intersect({0.2, 0.2, -1e-12}, {0.5, 0.2, 1}, {0.2, 0.5, 1}));
  // A corner 1e-12 beyond the long edge x + y = 1, in the plane: a near miss.
  EXPECT_FALSE(separate_triangles_intersect({0.5 + 1e-12, 0.5 + 1e-12, 0}, {1, 1, 0}, {1, 1, 1}));
  EXPECT_TRUE(separate_triangles_intersect({0.5, 0.5, 0}, {1, 1, 0}, {1, 1, 1}));
  // Coplanar overlap, and coplanar but apart.
  EXPECT_TRUE(separate_triangles_intersect({0.1, 0.1, 0}, {0.6, 0.1, 0}, {0.1, 0.6, 0}));
  EXPECT_FALSE(separate_triangles_intersect({2.1, 0.1, 0}, {2.6, 0.1, 0}, {2.1, 0.6, 0}));
}

TEST(IntersectionCheck, TrianglesSharingOneVertex) {
  // Fanning away from each other, in the plane and out of it.
  EXPECT_FALSE(triangles_sharing_the_origin_intersect({-1, 0, 0}, {0, -1, 0}));
  EXPECT_FALSE(triangles_sharing_the_origin_intersect({-1, 0, 0.5}, {0, -1, 0.5}));
  // Touching only at the shared corner, standing on the plane.
  EXPECT_FALSE(triangles_sharing_the_origin_intersect({-1, 0, 0}, {0, 0, 1}));
  // The edge opposite the shared corner passes through the other triangle.
  EXPECT_TRUE(triangles_sharing_the_origin_intersect({0.5, 0.2, 0.5}, {0.2, 0.5, -0.5}));
  // Coplanar, the wedges overlapping.
  EXPECT_TRUE(triangles_sharing_the_origin_intersect({0.5, 0.1, 0}, {0.1, 0.5, 0}));
  // Standing on an edge of the other: they share the segment from the origin to (0.5, 0, 0).
  EXPECT_TRUE(triangles_sharing_the_origin_intersect({0.5, 0, 0}, {0, 0, 1}));
  // Folded 1e-12 short of touching that edge.
  EXPECT_FALSE(triangles_sharing_the_origin_intersect({0.5, 0, 1e-12}, {0, 0, 1}));
}

TEST(IntersectionCheck, TrianglesSharingAnEdge) {
  // Flat neighbours and a folded hinge meet only on their edge.
  EXPECT_FALSE(triangles_sharing_an_edge_intersect({1, 1, 0}));
  EXPECT_FALSE(triangles_sharing_an_edge_intersect({1, 1, 0.5}));
  // Folded almost shut, 1e-12 from flat: still only the edge.
  EXPECT_FALSE(triangles_sharing_an_edge_intersect({0.2, 0.2, 1e-12}));
  // Folded flat onto each other.
  EXPECT_TRUE(triangles_sharing_an_edge_intersect({0.2, 0.2, 0}));
}

TEST(IntersectionCheck, DuplicatedTriangleIntersects) {
  const TriMesh mesh = mesh_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 1}});
  EXPECT_EQ(find_intersections(mesh.vertices, mesh.triangles).intersecting_pairs, (Pairs{{0, 1}}));
}

TEST(IntersectionCheck, DegenerateTriangleIsReportedNotPaired) {
  // Triangle 1 is a segment piercing triangle 0.
  const TriMesh mesh =
      mesh_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, -1}, {0.2, 0.2, 0}, {0.2, 0.2, 1}},
              {{0, 1, 2}, {3, 4, 5}});
  const IntersectionReport report = find_intersections(mesh.vertices, mesh.triangles);
  EXPECT_EQ(report.degenerate_triangles, (std::vector<int>{1}));
  EXPECT_TRUE(report.intersecting_pairs.empty());
  EXPECT_FALSE(report.clean());
  EXPECT_NE(list_intersections(report, {}).find("triangle 1 is degenerate"), std::string::npos);
}

TEST(IntersectionCheck, SphereIsCleanUntilAVertexIsPushedThrough) {
  TriMesh sphere = make_sphere({.radius = 0.5, .edge_length = 0.05});
  const IntersectionReport clean = find_intersections(sphere.vertices, sphere.triangles);
  EXPECT_TRUE(clean.clean());
  EXPECT_EQ(clean.triangle_count, sphere.triangle_count());

  // The topmost vertex goes straight down, through the inside and out below the bottom.
  int top = 0;
  sphere.vertices.col(2).maxCoeff(&top);
  sphere.vertices.row(top) << 0, 0, -0.6;
  std::set<int> moved;  // the triangles around the pushed vertex
  for (int t = 0; t < sphere.triangle_count(); ++t)
    if ((sphere.triangles.row(t).array() == top).any()) moved.insert(t);

  const IntersectionReport pushed = find_intersections(sphere.vertices, sphere.triangles);
  ASSERT_FALSE(pushed.intersecting_pairs.empty());
  EXPECT_TRUE(pushed.degenerate_triangles.empty());
  for (const auto& [s, t] : pushed.intersecting_pairs) {
    // Exactly one side moved, and the other is where it was pushed through: the bottom cap.
    ASSERT_NE(moved.count(s), moved.count(t)) << s << " " << t;
    const int still = moved.count(s) ? t : s;
    for (int k = 0; k < 3; ++k)
      EXPECT_LT(sphere.vertices(sphere.triangles(still, k), 2), -0.4) << still;
  }
}

TEST(IntersectionCheck, ListingNamesPartsAndLocalIndicesAndStopsAtTheLimit) {
  const std::vector<TrianglePart> parts{{"shell 'a'", 0, 10}, {"collider 'b'", 10, 30}};
  EXPECT_EQ(describe_triangle(3, parts), "shell 'a' triangle 3");
  EXPECT_EQ(describe_triangle(12, parts), "collider 'b' triangle 2");
  EXPECT_EQ(describe_triangle(12, {}), "triangle 12");

  IntersectionReport report;
  for (int k = 0; k < 25; ++k) report.intersecting_pairs.push_back({k % 10, 10 + k});
  const std::string listing = list_intersections(report, parts);
  EXPECT_EQ(listing.rfind("25 intersecting triangle pairs:\n", 0), 0u) << listing;
  EXPECT_NE(listing.find("  shell 'a' triangle 1 and collider 'b' triangle 1\n"), std::string::npos)
      << listing;
  EXPECT_NE(listing.find("  shell 'a' triangle 9 and collider 'b' triangle 19\n"),
            std::string::npos);
  EXPECT_EQ(listing.find("collider 'b' triangle 20\n"), std::string::npos)
      << "pair 21 is not listed";
  EXPECT_NE(listing.find("  ... and 5 more\n"), std::string::npos) << listing;
  EXPECT_EQ(std::count(listing.begin(), listing.end(), '\n'), 22);
}

TEST(IntersectionCheck, RequireIntersectionFreeThrowsWithTheListing) {
  const TriMesh crossing =
      mesh_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, -0.5}, {0.3, 0.2, 0.5}, {0.2, 0.3, 0.5}},
              {{0, 1, 2}, {3, 4, 5}});
  const std::vector<TrianglePart> parts{{"shell 'floor'", 0, 1}, {"shell 'spike'", 1, 1}};
  try {
    require_intersection_free(crossing, "scene.toml", parts);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("scene.toml: ", 0), 0u) << message;
    EXPECT_NE(message.find("shell 'floor' triangle 0 and shell 'spike' triangle 0"),
              std::string::npos)
        << message;
  }
  const TriMesh apart = mesh_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}},
                                {{0, 1, 2}, {3, 4, 5}});
  EXPECT_NO_THROW(require_intersection_free(apart, "scene.toml", parts));
}

}  // namespace
}  // namespace psq
