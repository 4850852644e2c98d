#include "engine/progressive/relaxation_patch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "engine/progressive/target_relaxation.hpp"

namespace psq {
namespace {

constexpr double kStart = 1e-6, kSafeGap = 1e-4, kActivation = 1e-3;

// Body 0: a fixed triangle, and another 10 m away; body 1: a triangle kStart above the first,
// its targets 1 cm below it (the scene of target_relaxation_test.cpp with a far triangle added).
ContactSurface surface_with_a_far_triangle() {
  ContactSurface surface;
  surface.triangles.resize(3, 3);
  surface.triangles << 0, 1, 2, 3, 4, 5, 6, 7, 8;
  surface.edges = {{0, 1}, {1, 2}, {0, 2}, {3, 4}, {4, 5}, {3, 5}, {6, 7}, {7, 8}, {6, 8}};
  surface.vertex_body = {0, 0, 0, 1, 1, 1, 0, 0, 0};
  surface.may_touch = [](int a, int b) { return a != b; };
  surface.rest.resize(9, 3);
  surface.rest << 0, 0, 0, 1, 0, 0, 0, 1, 0,                                //
      0.2, 0.2, kStart, 0.6, 0.2, kStart, 0.2, 0.6, kStart,                 //
      10, 10, 0, 11, 10, 0, 10, 11, 0;
  return surface;
}

Positions targets_through_the_obstacle(const Positions& x) {
  Positions target = x;
  for (int v = 3; v < 6; ++v) target(v, 2) = -1e-2;
  return target;
}

TEST(RelaxationPatch, ConfinementCutsTheStepAtTheBoxFaceAndIgnoresUnconfinedVertices) {
  Confinement confinement;
  confinement.boxes = {Eigen::AlignedBox3d(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones())};
  confinement.box_of = {0, -1};
  Eigen::VectorXd x(6), dx(6);
  x << 0.5, 0.5, 0.5, 0.5, 0.5, 0.5;
  dx << 0.0, -4.0, 0.0, 100.0, 0.0, 0.0;  // vertex 0 leaves through y = 0 at t = 1/8
  EXPECT_DOUBLE_EQ(confinement.max_step(x, dx), 0.125);
  dx << 0.1, 0.1, -0.1, 100.0, 0.0, 0.0;  // vertex 0 stays inside for the full step
  EXPECT_DOUBLE_EQ(confinement.max_step(x, dx), 1.0);
}

TEST(RelaxationPatch, KeepsThePrimitivesWithinReachAndConfinesTheFreedVertices) {
  const ContactSurface surface = surface_with_a_far_triangle();
  const Positions target = targets_through_the_obstacle(surface.rest);
  const std::vector<bool> freed{false, false, false, true, true, true, false, false, false};
  const RelaxationPatch patch = relaxation_patch(surface, surface.rest, target, freed, kActivation);

  EXPECT_EQ(patch.vertex, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(patch.surface.triangles.rows(), 2);
  // The moving triangle's edges and the fixed one's hypotenuse; its legs along x = 0 and y = 0
  // lie 0.2 m from the freed vertices, beyond their box (1.1 cm around them and their targets).
  EXPECT_EQ(patch.surface.edges.size(), 4u);
  EXPECT_EQ(patch.freed, (std::vector<bool>{false, false, false, true, true, true}));
  ASSERT_EQ(patch.confinement.boxes.size(), 1u);
  EXPECT_EQ(patch.confinement.box_of, (std::vector<int>{-1, -1, -1, 0, 0, 0}));
  for (int v = 3; v < 6; ++v) {
    EXPECT_TRUE(patch.confinement.boxes[0].contains(surface.rest.row(v).transpose()));
    EXPECT_TRUE(patch.confinement.boxes[0].contains(target.row(v).transpose()));
  }
}

// The patch's relaxation must end where the whole surface's does: the far triangle is beyond
// the barrier's reach of anything the freed vertices can touch.
TEST(RelaxationPatch, RelaxesLikeTheWholeSurface) {
  const ContactSurface surface = surface_with_a_far_triangle();
  const Positions target = targets_through_the_obstacle(surface.rest);
  ContactParameters parameters;
  parameters.band.activation_distance = kActivation;
  const double diagonal = bounding_box_diagonal(surface.rest);

  ContactTerm whole(surface, parameters, std::nullopt, diagonal, 1.0);
  Eigen::VectorXd expected = flat(surface.rest);
  const RelaxationStats whole_stats = relax_free_vertices(
      whole, flat(target), DofMap(9, {0, 1, 2, 6, 7, 8}), kSafeGap, expected);

  Positions x = surface.rest;
  const std::vector<bool> freed{false, false, false, true, true, true, false, false, false};
  const RelaxationStats stats =
      relax_on_patch(surface, parameters, std::nullopt, diagonal, freed, target, kSafeGap, x);

  EXPECT_EQ(stats.vertices, 3);
  EXPECT_EQ(whole_stats.vertices, 3);
  for (int v = 3; v < 6; ++v) {
    EXPECT_GE(x(v, 2), 0.5 * kSafeGap) << "vertex " << v;
    EXPECT_NEAR(x(v, 2), expected(3 * v + 2), 1e-3 * kSafeGap) << "vertex " << v;
  }
  for (int v : {0, 1, 2, 6, 7, 8})
    EXPECT_EQ(x.row(v), surface.rest.row(v)) << "held vertex " << v;
}

}  // namespace
}  // namespace psq
