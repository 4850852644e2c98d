#pragma once
// The deformation gradient of a shell triangle and its pull-back to the triangle's vertices,
// shared by the energies that are functions of it (membrane.hpp, strain_limit.hpp):
//   F = E D⁻¹,  E = [x1 − x0, x2 − x0] the current edge matrix, D the rest edges in an
//   orthonormal frame of the rest triangle (DᵀD = ā = ĒᵀĒ).
// An energy w·ψ(F) of a triangle has gradient w·Aᵀ vec(∂ψ/∂F) and Hessian w·Aᵀ (∂²ψ/∂F²) A,
// A = ∂vec(F)/∂x constant per triangle.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

using DeformationGradient = Eigen::Matrix<double, 3, 2>;
using DeformationGradientVector = Eigen::Matrix<double, 6, 1>;  ///< column-major vec(F)
using DeformationGradientMatrix = Eigen::Matrix<double, 6, 6>;  ///< on column-major vec(F)
/// Positions of a triangle's vertices as columns x0, x1, x2.
using TrianglePositions = Eigen::Matrix3d;
using TriangleVector = Eigen::Matrix<double, 9, 1>;
using TriangleMatrix = Eigen::Matrix<double, 9, 9>;

/// Rest data of one triangle.
struct MembraneRest {
  Eigen::Matrix2d rest_frame_inverse;  ///< D⁻¹ with DᵀD = ā (D upper triangular)
  double area;                         ///< Ā
};

/// Rest data of a triangle. A degenerate rest triangle gets area 0 and an unusable frame.
MembraneRest membrane_rest(const TrianglePositions& rest);

/// F = [x1 − x0, x2 − x0] D⁻¹.
DeformationGradient deformation_gradient(const TrianglePositions& x, const MembraneRest& rest);

/// vec(a bᵀ) for a 3×2 matrix stored column by column.
DeformationGradientVector vec_outer(const Eigen::Vector3d& a, const Eigen::Vector2d& b);

/// A = ∂vec(F)/∂(x0, x1, x2): block (k, i) is β_i[k]·I, β1, β2 the rows of D⁻¹,
/// β0 = −β1 − β2.
Eigen::Matrix<double, 6, 9> deformation_gradient_jacobian(const MembraneRest& rest);

/// w·Aᵀ vec(P): the gradient of a triangle energy w·ψ(F) from its stress P = ∂ψ/∂F,
/// i.e. w·(P β0, P β1, P β2).
TriangleVector pull_back_stress(const DeformationGradient& stress, const MembraneRest& rest,
                                double weight);

/// w·Aᵀ H A: the Hessian of a triangle energy w·ψ(F) from H = ∂²ψ/∂F². A is onto, so the
/// result is PSD when H is.
TriangleMatrix pull_back_stress_derivative(const DeformationGradientMatrix& stress_derivative,
                                           const MembraneRest& rest, double weight);

/// The triangles of one shell as elements of a scene's global position vector x (size 3N):
/// each one's rest data and stencil, the shell's local vertex i being global vertex
/// vertex_offset + i.
class TriangleElements {
 public:
  /// Precomputes every triangle's rest data. Throws InputError, its message starting with
  /// `term`, for a zero-area rest triangle.
  TriangleElements(const TriMesh& rest, int vertex_offset, const char* term);

  [[nodiscard]] std::size_t size() const { return rest_.size(); }
  [[nodiscard]] const MembraneRest& rest(std::size_t t) const { return rest_[t]; }
  /// 3 global vertices per triangle.
  [[nodiscard]] const std::vector<int>& stencils() const { return stencils_; }
  /// Triangle t's vertices gathered from x (or from a step of the same layout).
  [[nodiscard]] TrianglePositions positions(const Eigen::VectorXd& x, std::size_t t) const;

 private:
  std::vector<int> stencils_;
  std::vector<MembraneRest> rest_;
};

}  // namespace psq
