#pragma once
// Squared distances of the point–point and point–edge sub-cases, and the closest-pair calculus
// that gives every sub-case (point–plane and line–line too) its gradient and Hessian.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "engine/contact/distance_type.hpp"

namespace psq {

/// Derivatives of a squared distance between two affine features (points, lines, planes).
/// The vector between their closest points is an affine combination of the N stencil
/// vertices, q = Σᵢ wᵢ xᵢ, whose weights are affine in the K free closest-point parameters y
/// (A = ∂w/∂y, constant); the distance is d(x) = min_y ‖q(x, y)‖². At the minimiser
/// Jᵀq = 0 with J = ∂q/∂y = X A, and by the envelope and implicit-function theorems
///   ∇d = 2 w ⊗ q,   ∇²d = 2 (w wᵀ) ⊗ I₃ − 2 Bᵀ G⁻¹ B,
/// where G = JᵀJ and B (K × 3N) has block (k, i) = A_ik qᵀ + wᵢ J_kᵀ, the derivative of the
/// optimality condition J_kᵀq with respect to xᵢ. G⁻¹ is formed with the cross product
/// (det G = ‖J₀ × J₁‖² for K = 2) so nearly degenerate pairs keep their digits.
/// `x` holds the vertices as columns, `w` the weights at the minimiser and `q` = X w (passed
/// in so callers can supply a more accurate evaluation). G must be invertible.
template <int N, int K>
StencilDerivatives<3 * N> closest_pair_distance_derivatives(
    const Eigen::Matrix<double, 3, N>& x, const Eigen::Matrix<double, N, 1>& w,
    const Eigen::Matrix<double, N, K>& dw_dy, const Eigen::Vector3d& q) {
  StencilDerivatives<3 * N> d;
  d.value = q.squaredNorm();
  for (int i = 0; i < N; ++i) {
    d.gradient.template segment<3>(3 * i) = 2 * w[i] * q;
    for (int j = 0; j < N; ++j)
      d.hessian.template block<3, 3>(3 * i, 3 * j).diagonal().setConstant(2 * w[i] * w[j]);
  }
  if constexpr (K > 0) {
    const Eigen::Matrix<double, 3, K> J = x * dw_dy;
    Eigen::Matrix<double, K, K> G_inverse;
    if constexpr (K == 1) {
      G_inverse(0, 0) = 1 / J.squaredNorm();
    } else {
      static_assert(K == 2, "features are points, lines or planes");
      const double det = J.col(0).cross(J.col(1)).squaredNorm();
      G_inverse << J.col(1).squaredNorm(), -J.col(0).dot(J.col(1)), -J.col(0).dot(J.col(1)),
          J.col(0).squaredNorm();
      G_inverse /= det;
    }
    Eigen::Matrix<double, K, 3 * N> B;
    for (int k = 0; k < K; ++k)
      for (int i = 0; i < N; ++i)
        B.template block<1, 3>(k, 3 * i) =
            dw_dy(i, k) * q.transpose() + w[i] * J.col(k).transpose();
    d.hessian -= 2 * B.transpose() * G_inverse * B;
  }
  return d;
}

/// The derivatives of a function of M of a stencil's N vertices, placed in the full stencil:
/// the function's vertex k is the stencil's vertex slots[k].
template <int N, int M>
StencilDerivatives<3 * N> embed_in_stencil(const StencilDerivatives<3 * M>& part,
                                           const std::array<int, M>& slots) {
  StencilDerivatives<3 * N> full;
  full.value = part.value;
  for (int a = 0; a < M; ++a) {
    full.gradient.template segment<3>(3 * slots[a]) = part.gradient.template segment<3>(3 * a);
    for (int b = 0; b < M; ++b)
      full.hessian.template block<3, 3>(3 * slots[a], 3 * slots[b]) =
          part.hessian.template block<3, 3>(3 * a, 3 * b);
  }
  return full;
}

/// d = ‖p − q‖².
double point_point_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& q);

/// d = ‖p − q‖², ∇d = 2 (p − q, q − p), ∇²d = 2 [I −I; −I I]. Stencil (p, q).
StencilDerivatives<6> point_point_distance_derivatives(const Eigen::Vector3d& p,
                                                       const Eigen::Vector3d& q);

/// The foot of p on the line through e0 and e1: its parameter α = (p − e0)·e/‖e‖² along
/// e = e1 − e0 and the vector q = p − (e0 + α e) from the foot to p. The edge must have nonzero
/// length.
struct LineFoot {
  double alpha;
  Eigen::Vector3d q;
};

/// The foot of p on the line through e0 and e1.
LineFoot line_foot(const Eigen::Vector3d& p, const Eigen::Vector3d& e0, const Eigen::Vector3d& e1);

/// Squared distance from p to the LINE through e0 and e1: d = ‖p − e0 − α e‖² with
/// e = e1 − e0 and α = (p − e0)·e/‖e‖². The edge must have nonzero length.
double point_line_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                           const Eigen::Vector3d& e1);

/// point_line_distance with its derivatives over the stencil (p, e0, e1): with the weights
/// w = (1, α − 1, −α) and q = p − e0 − α e,
///   ∇d = 2 w ⊗ q,   ∇²d = 2 (w wᵀ) ⊗ I₃ − 2 ‖e‖² ∇α ∇αᵀ
/// (closest_pair_distance_derivatives with one parameter, α).
StencilDerivatives<9> point_line_distance_derivatives(const Eigen::Vector3d& p,
                                                      const Eigen::Vector3d& e0,
                                                      const Eigen::Vector3d& e1);

/// Squared distance from p to the segment (e0, e1), through point_edge_case.
double point_edge_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                           const Eigen::Vector3d& e1);
/// The same, given the case point_edge_case(p, e0, e1) already found.
double point_edge_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                           const Eigen::Vector3d& e1, PointEdgeCase edge_case);

/// point_edge_distance with its derivatives over the stencil (p, e0, e1), zero for the
/// endpoint the distance does not depend on.
StencilDerivatives<9> point_edge_distance_derivatives(const Eigen::Vector3d& p,
                                                      const Eigen::Vector3d& e0,
                                                      const Eigen::Vector3d& e1);

/// Positions of a 4-vertex contact stencil as columns: (p, t0, t1, t2) for point–triangle,
/// (ea0, ea1, eb0, eb1) for edge–edge.
using StencilPositions = Eigen::Matrix<double, 3, 4>;

/// The four vertices of a point–triangle or edge–edge pair as the columns of one matrix.
inline StencilPositions stack_stencil(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  StencilPositions x;
  x << a, b, c, d;
  return x;
}

/// The closest points a and b of the two features of a 4-vertex stencil's interior case (a
/// point and a plane, or two lines). They are found through the features' common normal rather
/// than a Gram-matrix solve, which keeps q accurate when the features nearly touch.
struct ClosestPair {
  Eigen::Vector4d weights;  ///< w with Σ wᵢ xᵢ = a − b: affine weights of a, minus those of b
  Eigen::Vector3d normal;   ///< the common normal of the features (not normalized)
  Eigen::Vector3d q;        ///< a − b, computed along the normal
};

/// A point–point or point–edge sub-case of a 4-vertex stencil: the stencil vertex that is the
/// point, and the one stencil vertex (feature_size 1) or the two edge endpoints (feature_size
/// 2, measured to the edge's line) it is measured to.
struct PointFeature {
  int point;
  int feature_size;
  std::array<int, 2> feature;
};

/// The point–point or point–edge sub-case of a point–triangle boundary case (any case but
/// Face), in the stencil slots (p, t0, t1, t2) = (0, 1, 2, 3).
const PointFeature& point_feature(PointTriangleCase boundary_case);

/// The point–point or point–edge sub-case of an edge–edge boundary case (any case but
/// LineLine), in the stencil slots (ea0, ea1, eb0, eb1) = (0, 1, 2, 3).
const PointFeature& point_feature(EdgeEdgeCase boundary_case);

/// The squared distance of a point–point or point–edge sub-case of a stencil.
double point_feature_distance(const PointFeature& sub_case, const StencilPositions& x);

/// point_feature_distance with its derivatives over the whole 4-vertex stencil.
StencilDerivatives<12> point_feature_distance_derivatives(const PointFeature& sub_case,
                                                          const StencilPositions& x);

}  // namespace psq
