#pragma once
// The slope of tilted_plane (jobs/scenes/tilted_plane.toml) and a rigid block's quasistatic step
// down it, for the tests that slide its patch: the inertia-like term m/(2Δt²)‖x − xᵗ‖², the
// weight and Coulomb friction μN give Δt² g (sin α − μ cos α) per step when μ < tan α.

#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "engine/scene/scene.hpp"

namespace psq::test {

/// α, the slope's tilt (its collider's rotation about x).
inline double slope_angle(const Scene& scene) {
  return scene.colliders.at(0).mesh.rotation_degrees * std::numbers::pi / 180;
}

/// The unit direction down the slope, in its plane.
inline Eigen::Vector3d downhill(const Scene& scene) {
  const double alpha = slope_angle(scene);
  return {0, -std::cos(alpha), -std::sin(alpha)};
}

/// Δt² g (sin α − μ cos α): a rigid block's quasistatic step down the slope, g the scene's.
inline double coulomb_step(const Scene& scene, double mu) {
  const double alpha = slope_angle(scene);
  const double dt = scene.time.step;
  return dt * dt * scene.gravity.norm() * (std::sin(alpha) - mu * std::cos(alpha));
}

}  // namespace psq::test
