#include "engine/progressive/target_relaxation.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace psq {
namespace {

// A triangle held 1e-6 m above a fixed one, its targets 1 cm below the fixed one: the pull drives
// it through, the barrier holds it above. The relaxation must end with the pair at least g/2
// apart (§4.4.3: the barrier stiffness grows until the gap is restored), above the fixed
// triangle, and inside the barrier's reach (the pull still acts).
TEST(TargetRelaxation, RestoresTheSafeGapAgainstAPullThroughAnObstacle) {
  constexpr double kStart = 1e-6, kSafeGap = 1e-4, kActivation = 1e-3;
  ContactSurface surface;
  surface.triangles.resize(2, 3);
  surface.triangles << 0, 1, 2, 3, 4, 5;
  surface.edges = {{0, 1}, {1, 2}, {0, 2}, {3, 4}, {4, 5}, {3, 5}};
  surface.vertex_body = {0, 0, 0, 1, 1, 1};
  surface.may_touch = [](int a, int b) { return a != b; };
  surface.rest.resize(6, 3);
  surface.rest << 0, 0, 0, 1, 0, 0, 0, 1, 0,  //
      0.2, 0.2, kStart, 0.6, 0.2, kStart, 0.2, 0.6, kStart;
  ContactParameters parameters;
  parameters.band.activation_distance = kActivation;
  ContactTerm contact(surface, parameters, std::nullopt, std::sqrt(2.0), 1.0);

  Eigen::VectorXd x = flat(surface.rest);
  Eigen::VectorXd target = x;
  for (int v = 3; v < 6; ++v) target(3 * v + 2) = -1e-2;
  const DofMap dofs(6, {0, 1, 2});
  const RelaxationStats stats = relax_free_vertices(contact, target, dofs, kSafeGap, x);

  EXPECT_EQ(stats.vertices, 3);
  for (int v = 3; v < 6; ++v) {
    EXPECT_GE(x(3 * v + 2), 0.5 * kSafeGap) << "vertex " << v;
    EXPECT_LT(x(3 * v + 2), kActivation) << "vertex " << v;
  }
  for (int v = 0; v < 3; ++v)
    EXPECT_EQ(x.segment<3>(3 * v), flat(surface.rest).segment<3>(3 * v)) << "held vertex " << v;
}

}  // namespace
}  // namespace psq
