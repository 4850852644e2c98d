#pragma once
// IPC's mollifier for nearly parallel edge–edge pairs (Li et al. 2020). As two edges turn
// through parallel their closest pair jumps and the edge–edge distance is not smooth there;
// multiplying the edge–edge barrier by a mollifier that vanishes with the squared sine of the
// edges' angle makes the product smooth enough (C¹) for Newton.

#include <Eigen/Core>

#include "engine/contact/distance_type.hpp"

namespace psq {

/// ε_x = 1e-3 ‖ēa‖² ‖ēb‖²: the mollifier's threshold on c, from the edges' REST positions, so
/// that it is a fixed fraction (sin²θ below 1e-3) of the rest configuration's scale.
double edge_edge_mollifier_threshold(const Eigen::Vector3d& ea0_rest,
                                     const Eigen::Vector3d& ea1_rest,
                                     const Eigen::Vector3d& eb0_rest,
                                     const Eigen::Vector3d& eb1_rest);

/// c = ‖n‖², n = u × v with u = ea1 − ea0, v = eb1 − eb0 (c = ‖u‖²‖v‖² sin²θ), and its
/// derivatives over (ea0, ea1, eb0, eb1). With [a]× the cross-product matrix:
///   ∂c/∂u = 2 v × n,   ∂c/∂v = 2 n × u,
///   ∂²c/∂u² = 2 (‖v‖² I − v vᵀ),   ∂²c/∂v² = 2 (‖u‖² I − u uᵀ),
///   ∂²c/∂u∂v = 2 ([v]× [u]× − [n]×),
/// and ∂/∂ea0 = −∂/∂u, ∂/∂ea1 = ∂/∂u (likewise for b).
StencilDerivatives<12> edge_edge_cross_squared_norm(const Eigen::Vector3d& ea0,
                                                    const Eigen::Vector3d& ea1,
                                                    const Eigen::Vector3d& eb0,
                                                    const Eigen::Vector3d& eb1);

/// m(c) = (2 − c/ε_x) c/ε_x for c < ε_x, 1 for c ≥ ε_x: 0 for parallel edges, C¹ at ε_x.
double edge_edge_mollifier(double c, double threshold);

/// m′(c) = 2/ε_x (1 − c/ε_x) for c < ε_x, 0 beyond.
double edge_edge_mollifier_first_derivative(double c, double threshold);

/// m″(c) = −2/ε_x² for c < ε_x, 0 beyond.
double edge_edge_mollifier_second_derivative(double c, double threshold);

/// m(c(x)) with its derivatives over (ea0, ea1, eb0, eb1) (chain_rule).
/// Exactly 1 with zero derivatives for pairs further from parallel than the threshold.
StencilDerivatives<12> edge_edge_mollifier(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                           const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1,
                                           double threshold);

}  // namespace psq
