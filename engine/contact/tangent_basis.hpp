#pragma once
// The tangent frame of a contact, as lagged friction needs it (Li et al. 2020, "Incremental
// Potential Contact", §5): the plane in which the two sides of a contact slide past each
// other, and the weights that turn the stencil's vertex motions into the relative motion of
// the two closest points.
//
// For a stencil whose closest points are a = Σ_{i∈A} αᵢ xᵢ and b = Σ_{i∈B} βᵢ xᵢ (affine
// combinations, Σαᵢ = Σβᵢ = 1), the weights are wᵢ = αᵢ on side A and −βᵢ on side B, so
// Σ wᵢ xᵢ = a − b is the vector between the closest points (the `q` of
// closest_pair_distance_derivatives, whose weights these are) and Σ wᵢ Δxᵢ the relative
// displacement of the two closest points. Vertices the closest features do not involve have
// weight 0.

#include <Eigen/Core>

#include "engine/contact/distance_type.hpp"
#include "engine/contact/point_edge_distance.hpp"

namespace psq {

/// Two orthonormal columns spanning a plane.
using TangentBasis = Eigen::Matrix<double, 3, 2>;

/// An orthonormal basis of the plane orthogonal to `normal` (which must be nonzero; its
/// length does not matter). The first column is normal × eₖ normalized, eₖ the coordinate
/// axis least aligned with the normal (no cancellation), the second completes a right-handed
/// frame (t₀ × t₁ ∥ normal). Friction only uses ‖Tᵀv‖, which is the same for every
/// orthonormal basis of the plane, so the in-plane orientation is free.
TangentBasis tangent_basis(const Eigen::Vector3d& normal);

/// The frame of one contact at the lagged state: the tangent basis T of the contact plane
/// (orthogonal to the vector between the closest points) and the closest-point weights w of
/// the stencil's four vertices. The relative tangential displacement of a step is
///   u = Tᵀ Σᵢ wᵢ (xᵢ − xᵢᵗ)   (a 2-vector).
struct ContactFrame {
  TangentBasis basis;
  Eigen::Vector4d weights;
};

/// The frame of a point–point or point–edge sub-case (PointFeature, slots of a 4-vertex
/// stencil): normal along the vector from the closest point of the feature to the point;
/// weights 1 on the point and −1 (point–point) or −(1 − α), −α (point–line, α the foot's
/// parameter along the edge) on the feature.
ContactFrame point_feature_frame(const PointFeature& sub_case, const StencilPositions& x);

/// The frame of a point–triangle stencil (p, t0, t1, t2) for its closest-feature case. Face:
/// normal along the triangle normal (t1 − t0) × (t2 − t0), weights (1, −b₀, −b₁, −b₂) with
/// (b₀, b₁, b₂) the barycentric coordinates of p's foot on the plane; otherwise the frame of
/// the vertex or edge sub-case (point_feature_frame).
ContactFrame point_triangle_frame(const StencilPositions& x, PointTriangleCase sub_case);

/// point_triangle_frame for the case point_triangle_case picks at x.
ContactFrame point_triangle_frame(const StencilPositions& x);

/// The frame of an edge–edge stencil (ea0, ea1, eb0, eb1) for its closest-feature case.
/// LineLine: normal along u × v (u = ea1 − ea0, v = eb1 − eb0), weights (1 − s, s, −(1 − t),
/// −t) with ea0 + s u and eb0 + t v the closest points of the lines; otherwise (parallel
/// edges included) the frame of the endpoint or endpoint–edge sub-case.
ContactFrame edge_edge_frame(const StencilPositions& x, EdgeEdgeCase sub_case);

/// edge_edge_frame for the case edge_edge_case picks at x.
ContactFrame edge_edge_frame(const StencilPositions& x);

}  // namespace psq
