#pragma once
// Squared distance between a point and a triangle, with its gradient and Hessian over the
// 4-vertex stencil (p, t0, t1, t2), whatever the closest feature.

#include <Eigen/Core>

#include "engine/contact/distance_type.hpp"
#include "engine/contact/point_edge_distance.hpp"

namespace psq {

/// The closest pair of p and the PLANE of the triangle (t0, t1, t2): normal n = e₁ × e₂
/// (eᵢ = tᵢ − t0), the foot's barycentric coordinates (1 − β₁ − β₂, β₁, β₂) with
/// β₁ = n·((p − t0) × e₂)/‖n‖² and β₂ = n·(e₁ × (p − t0))/‖n‖², weights
/// w = (1, β₁ + β₂ − 1, −β₁, −β₂) over (p, t0, t1, t2) and q = p − foot = n (n·(p − t0))/‖n‖².
/// The triangle must not be degenerate.
ClosestPair point_plane_closest_pair(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                                     const Eigen::Vector3d& t1, const Eigen::Vector3d& t2);

/// Squared distance from p to the PLANE of the triangle: d = (n·(p − t0))²/‖n‖² with
/// n = (t1 − t0) × (t2 − t0). The triangle must not be degenerate.
double point_plane_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                            const Eigen::Vector3d& t1, const Eigen::Vector3d& t2);

/// point_plane_distance with its derivatives over (p, t0, t1, t2). With the weights w and the
/// normal offset q of point_plane_closest_pair,
///   ∇d = 2 w ⊗ q,   ∇²d = 2 (w wᵀ) ⊗ I₃ − 2 Bᵀ G⁻¹ B
/// (closest_pair_distance_derivatives with the parameters β₁, β₂; G is the Gram matrix of
/// e₁, e₂).
StencilDerivatives<12> point_plane_distance_derivatives(const Eigen::Vector3d& p,
                                                        const Eigen::Vector3d& t0,
                                                        const Eigen::Vector3d& t1,
                                                        const Eigen::Vector3d& t2);

/// Squared distance from p to the triangle (t0, t1, t2), by point_triangle_case: a
/// point–point, point–line or point–plane distance.
double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                               const Eigen::Vector3d& t1, const Eigen::Vector3d& t2);

/// point_triangle_distance with its derivatives over (p, t0, t1, t2), zero for the vertices
/// the closest feature does not involve.
StencilDerivatives<12> point_triangle_distance_derivatives(const Eigen::Vector3d& p,
                                                           const Eigen::Vector3d& t0,
                                                           const Eigen::Vector3d& t1,
                                                           const Eigen::Vector3d& t2);

}  // namespace psq
