#pragma once
// Per-triangle kernels of the shell prolongation (paper §4.3, footnote 2): the rest frame in
// which offsets are stored, the deformed normal and rotation factor that carry them, and the
// exact gradient of the offsets.

#include <Eigen/Core>

namespace psq {

using Matrix32d = Eigen::Matrix<double, 3, 2>;

/// Rest data of one coarse triangle with rest vertices X0, X1, X2.
struct RestTriangleFrame {
  /// B⁻¹ with B = [[|ē₁|, ē₁·ē₂/|ē₁|], [0, |ē₁×ē₂|/|ē₁|]], ē_k = X_k − X0: the rest edges
  /// expressed in the frame (ê₁, ê₂), so that F = [x₁−x₀, x₂−x₀] B⁻¹ is the 3×2 deformation
  /// gradient and F = [ê₁, ê₂] at rest.
  Eigen::Matrix2d b_inverse;
  Eigen::Vector3d e1;      ///< ê₁ = ē₁/|ē₁|
  Eigen::Vector3d e2;      ///< ê₂ = n̄ × ê₁
  Eigen::Vector3d normal;  ///< n̄ = ē₁×ē₂/|ē₁×ē₂|
};

/// The rest frame; returns false (frame unset) for a triangle of zero area.
bool rest_triangle_frame(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                         const Eigen::Vector3d& x2, RestTriangleFrame& frame);

/// What the offsets of one deformed triangle need: n(x), R(F(x)) and the factors of the
/// polar decomposition F = R Ŝ used by the gradient.
struct DeformedTriangleFrame {
  Matrix32d rotation;             ///< R = U [I₂; 0] Vᵀ for F = U Σ Vᵀ
  Eigen::Vector3d normal;         ///< n = (x₁−x₀)×(x₂−x₀)/|…| (= r₁×r₂)
  Eigen::Vector3d edge1, edge2;   ///< x₁−x₀, x₂−x₀
  double normal_length = 0;       ///< |edge1 × edge2|, floored away from zero
  Eigen::Matrix2d stretch_inverse;  ///< Ŝ⁻¹ = V Σ⁻¹ Vᵀ, σ₂ floored away from zero
  double stretch_trace = 0;       ///< tr Ŝ = σ₁ + σ₂, floored away from zero
};

/// Deformed frame of the triangle x0, x1, x2. Near rank deficiency (σ₂ ≤ 1e-12 σ₁) the normal
/// falls back to a unit vector orthogonal to the stretched direction and the floors keep
/// every quantity finite: no NaN, although the derivative there is only a bounded surrogate.
DeformedTriangleFrame deformed_triangle_frame(const Eigen::Vector3d& x0,
                                              const Eigen::Vector3d& x1,
                                              const Eigen::Vector3d& x2,
                                              const Eigen::Matrix2d& b_inverse);

/// The offset a = n γ + R t of one target in a deformed triangle.
inline Eigen::Vector3d shell_offset(const DeformedTriangleFrame& frame, double gamma,
                                    const Eigen::Vector2d& t) {
  return frame.normal * gamma + frame.rotation * t;
}

/// Gradient of φ = Σ_i g_iᵀ a_i(x) over the targets i of one triangle with respect to its
/// three vertices (column k: ∂φ/∂x_k), given only the sums q = Σ γ_i g_i and K = Σ g_i t_iᵀ:
///   ∂φ/∂E = [ (β/tr Ŝ) [r₂, −r₁] + n (Ŝ⁻¹ Kᵀn)ᵀ ] B⁻ᵀ + [e₂×h, h×e₁],
///   β = ⟨R J, K⟩, J = [[0,−1],[1,0]], h = (I − n nᵀ) q / |e₁×e₂|,
/// from dR = R J ω + n (nᵀ dF Ŝ⁻¹) with ω = (r₂ᵀ dF₁ − r₁ᵀ dF₂)/tr Ŝ (polar decomposition
/// differentiated; JŜ + ŜJ = tr(Ŝ) J for symmetric 2×2 Ŝ), and ∂φ/∂x₀ = −∂φ/∂x₁ − ∂φ/∂x₂.
Eigen::Matrix3d offset_gradient(const DeformedTriangleFrame& frame,
                                const Eigen::Matrix2d& b_inverse, const Eigen::Vector3d& q,
                                const Matrix32d& k);

}  // namespace psq
