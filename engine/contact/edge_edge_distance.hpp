#pragma once
// Squared distance between two edges, with its gradient and Hessian over the 4-vertex stencil
// (ea0, ea1, eb0, eb1), whatever the closest features (parallel edges included).

#include <Eigen/Core>

#include "engine/contact/distance_type.hpp"
#include "engine/contact/point_edge_distance.hpp"

namespace psq {

/// The closest pair of the LINES through the edges: with u = ea1 − ea0, v = eb1 − eb0,
/// w₀ = ea0 − eb0 and the normal n = u × v, the closest points ea0 + s u and eb0 + t v have
/// s = n·(v × w₀)/‖n‖² and t = n·(u × w₀)/‖n‖²; weights w = (1 − s, s, t − 1, −t) over
/// (ea0, ea1, eb0, eb1) and q = n (n·w₀)/‖n‖² (evaluated so that it keeps its digits for nearly
/// parallel lines). The lines must not be parallel.
ClosestPair line_line_closest_pair(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                   const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1);

/// Squared distance between the LINES through the edges: d = (n·(ea0 − eb0))²/‖n‖² with
/// n = u × v, u = ea1 − ea0, v = eb1 − eb0. The lines must not be parallel.
double line_line_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                          const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1);

/// line_line_distance with its derivatives over (ea0, ea1, eb0, eb1). With the weights w and
/// the vector q between the closest points of line_line_closest_pair,
///   ∇d = 2 w ⊗ q,   ∇²d = 2 (w wᵀ) ⊗ I₃ − 2 Bᵀ G⁻¹ B
/// (closest_pair_distance_derivatives with the parameters s, t; G is the Gram matrix of
/// u, −v, det G = ‖n‖²).
StencilDerivatives<12> line_line_distance_derivatives(const Eigen::Vector3d& ea0,
                                                      const Eigen::Vector3d& ea1,
                                                      const Eigen::Vector3d& eb0,
                                                      const Eigen::Vector3d& eb1);

/// Squared distance between the edges (ea0, ea1) and (eb0, eb1), by edge_edge_case: a
/// point–point, point–line or line–line distance.
double edge_edge_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                          const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1);

/// edge_edge_distance with its derivatives over (ea0, ea1, eb0, eb1), zero for the vertices
/// the closest features do not involve.
StencilDerivatives<12> edge_edge_distance_derivatives(const Eigen::Vector3d& ea0,
                                                      const Eigen::Vector3d& ea1,
                                                      const Eigen::Vector3d& eb0,
                                                      const Eigen::Vector3d& eb1);

}  // namespace psq
