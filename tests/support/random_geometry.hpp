#pragma once
// Random points and contact stencils for tests, drawn in a fixed order so that a seed gives the
// same geometry with every compiler.

#include <Eigen/Core>
#include <random>

#include "engine/contact/point_edge_distance.hpp"

namespace psq::test {

/// A point with coordinates drawn uniformly from [−1, 1], x first. (A braced list fixes the
/// order of the draws; the arguments of a constructor call would be drawn in an unspecified one.)
inline Eigen::Vector3d random_point(std::mt19937& rng) {
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  return {coordinate(rng), coordinate(rng), coordinate(rng)};
}

/// Four random points (random_point, in order), the columns of a 4-vertex contact stencil.
inline StencilPositions random_stencil(std::mt19937& rng) {
  StencilPositions x;
  for (int i = 0; i < 4; ++i) x.col(i) = random_point(rng);
  return x;
}

}  // namespace psq::test
