#pragma once
// Neo-Hookean membrane energy of a shell (DESIGN.md §4), per triangle:
//   Ψ = h·Ā·ψ(F),  ψ(F) = μ/2 (‖F‖² − 2) − μ ln J + λ/2 (ln J)²,  J = √det(FᵀF),
// with F = E D⁻¹ the 3×2 deformation gradient (deformation_gradient.hpp): E = [x1 − x0, x2 − x0]
// the current edge matrix and D any 2×2 matrix with DᵀD = ā = ĒᵀĒ (ψ sees F only through FᵀF, so
// the choice of rest frame is free). Then ‖F‖² = tr(ā⁻¹a) and J² = det a / det ā, the formula of
// DESIGN.md. μ, λ are the plane-stress Lamé parameters.

#include <Eigen/Core>

#include "engine/core/element_matrices.hpp"
#include "engine/elastic/deformation_gradient.hpp"
#include "engine/elastic/lame.hpp"
#include "engine/elastic/material.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// ψ(F) as above; +∞ when det(FᵀF) ≤ 0 (a degenerate triangle), so line searches reject it.
double membrane_density(const DeformationGradient& F, const PlaneStressLame& lame);

/// ∂ψ/∂F = μ F + (λ ln J − μ) F (FᵀF)⁻¹. Throws NumericalError when det(FᵀF) ≤ 0.
DeformationGradient membrane_stress(const DeformationGradient& F, const PlaneStressLame& lame);

/// ∂²ψ/∂F² on vec(F), from its analytic eigensystem. With F = U Σ Vᵀ (U 3×2, singular values
/// σ1, σ2), n = u1 × u2 and c = λ ln J − μ, the eigenpairs are
///   scaling   span{u1 v1ᵀ, u2 v2ᵀ}:  the 2×2 Hessian of ψ in (σ1, σ2),
///             ψ_kk = μ + (λ − c)/σ_k², ψ_12 = λ/(σ1σ2);
///   twist     (u1 v2ᵀ − u2 v1ᵀ)/√2:  μ + c/(σ1σ2);
///   flip      (u1 v2ᵀ + u2 v1ᵀ)/√2:  μ − c/(σ1σ2);
///   normal    n v_kᵀ:                μ + c/σ_k²  (k = 1, 2).
/// With project_psd, negative eigenvalues are clamped to zero (the closest PSD matrix).
/// Throws NumericalError when det(FᵀF) ≤ 0.
DeformationGradientMatrix membrane_stress_derivative(const DeformationGradient& F,
                                                     const PlaneStressLame& lame, bool project_psd);

/// One triangle's energy h·Ā·ψ(F); +∞ for a degenerate triangle.
double membrane_triangle_energy(const TrianglePositions& x, const MembraneRest& rest,
                                const PlaneStressLame& lame, double thickness);

/// ∂Ψ/∂(x0, x1, x2) = h·Ā·Aᵀ vec(P), P = ∂ψ/∂F (pull_back_stress).
TriangleVector membrane_triangle_gradient(const TrianglePositions& x, const MembraneRest& rest,
                                          const PlaneStressLame& lame, double thickness);

/// ∂²Ψ/∂x² = h·Ā·Aᵀ (∂²ψ/∂F²) A (pull_back_stress_derivative). The map A is onto, so
/// projecting ∂²ψ/∂F² (6×6) makes the 9×9 block PSD, and leaves it unchanged when it already is.
TriangleMatrix membrane_triangle_hessian(const TrianglePositions& x, const MembraneRest& rest,
                                         const PlaneStressLame& lame, double thickness,
                                         bool project_psd);

/// The membrane energy of one shell inside a scene's global position vector x (size 3N):
/// the shell's local vertex i is global vertex vertex_offset + i.
class MembraneEnergy {
 public:
  /// Precomputes every triangle's rest data. Throws InputError for a zero-area rest triangle.
  MembraneEnergy(const TriMesh& rest, const Material& material, int vertex_offset = 0);

  /// Σ over triangles; +∞ if any triangle is degenerate. Throws NumericalError for
  /// non-finite positions.
  [[nodiscard]] double value(const Eigen::VectorXd& x) const;
  /// g += ∇Ψ(x). Throws NumericalError for non-finite positions or a degenerate triangle.
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// One 9×9 block per triangle (stencil: its three global vertices), PSD-projected unless
  /// project_psd is false. Reuses out's storage when its stencils already match.
  void hessian(const Eigen::VectorXd& x, ElementMatrices& out, bool project_psd = true) const;

  [[nodiscard]] int triangle_count() const { return static_cast<int>(triangles_.size()); }

 private:
  void check(const Eigen::VectorXd& x) const;

  PlaneStressLame lame_;
  double thickness_;
  int vertex_offset_;
  int vertex_count_;
  TriangleElements triangles_;
};

}  // namespace psq
