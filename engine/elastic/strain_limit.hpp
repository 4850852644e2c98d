#pragma once
// Strain limiting on the singular values of each triangle's deformation gradient (Li et al.
// 2021, "Codimensional Incremental Potential Contact", §6; Codim-IPC's INEXT.h). A barrier
// keeps every singular value σ of the 3×2 deformation gradient F (the membrane's F, see
// deformation_gradient.hpp) strictly below the limit s̄, acting only inside a band (ŝ, s̄):
//   S = κ_s Σ_triangles Ā Σ_{k=1,2} g(σ_k),   g(σ) = b̃((s̄ − σ)/δ),   δ = s̄ − ŝ,
//   b̃(r) = −(r − 1)² ln r  (0 < r < 1),   b̃ = 0 for r ≥ 1,   +∞ for r ≤ 0.
// b̃(r) = b(r, 1) is IPC's log barrier with unit activation (engine/core/log_barrier.hpp): g is
// C² at ŝ, positive, increasing and convex on (ŝ, s̄), and infinite at s̄. Ā is the rest area,
// κ_s (N/m) an energy per unit rest area.
//
// Stiffness (Codim-IPC): κ_s starts at a scene value (initial_strain_limit_stiffness gives a
// scale) and doubles, up to a cap, whenever the tightest triangle was within 1e-4 δ of the
// limit at two consecutive Newton iterates (update_strain_limit_stiffness): the barrier is
// then losing against the other forces. Feasibility is not left to κ_s: the line search takes
// its first trial step from max_feasible_step, which never steps onto or past the limit.

#include <Eigen/Core>
#include <vector>

#include "engine/core/element_matrices.hpp"
#include "engine/elastic/deformation_gradient.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Where the strain-limit barrier acts: σ ∈ (band_start, limit).
struct StrainLimitBand {
  double limit = 1.05;      ///< s̄: no singular value may reach it (> band_start)
  double band_start = 1.0;  ///< ŝ: the barrier is zero up to here (Codim-IPC: 1, unstretched)

  /// δ = s̄ − ŝ.
  [[nodiscard]] double width() const { return limit - band_start; }
};

/// Singular values σ₁ ≥ σ₂ ≥ 0 of F: the principal stretches of the triangle.
Eigen::Vector2d principal_stretches(const DeformationGradient& F);

/// g(σ) above; 0 for σ ≤ ŝ, +∞ for σ ≥ s̄.
double strain_limit_barrier(double sigma, const StrainLimitBand& band);

/// g′(σ) = −b̃′(r)/δ with b̃′(r) = (1 − r)(2 ln r + 1 − 1/r); ≥ 0, 0 for σ ≤ ŝ, +∞ at s̄.
double strain_limit_barrier_first_derivative(double sigma, const StrainLimitBand& band);

/// g″(σ) = b̃″(r)/δ² with b̃″(r) = −2 ln r + (1/r)(1/r + 2) − 3; ≥ 0, 0 for σ ≤ ŝ.
double strain_limit_barrier_second_derivative(double sigma, const StrainLimitBand& band);

/// φ(F) = g(σ₁) + g(σ₂); +∞ when σ₁ ≥ s̄.
double strain_limit_density(const DeformationGradient& F, const StrainLimitBand& band);

/// ∂φ/∂F = Σ_k g′(σ_k) u_k v_kᵀ (∂σ_k/∂F = u_k v_kᵀ with F = U Σ Vᵀ). Throws NumericalError
/// when σ₁ ≥ s̄.
DeformationGradient strain_limit_stress(const DeformationGradient& F, const StrainLimitBand& band);

/// ∂²φ/∂F² on vec(F) from its analytic eigensystem (φ is an isotropic function of F; n the
/// third column of the full U):
///   scaling  u_k v_kᵀ:                g″(σ_k)
///   twist    (u₁v₂ᵀ − u₂v₁ᵀ)/√2:      (g′(σ₁) + g′(σ₂))/(σ₁ + σ₂)
///   flip     (u₁v₂ᵀ + u₂v₁ᵀ)/√2:      (g′(σ₁) − g′(σ₂))/(σ₁ − σ₂)  → g″ as σ₂ → σ₁
///   normal   n v_kᵀ:                  g′(σ_k)/σ_k
/// All are ≥ 0 (g′ ≥ 0 and increasing); with project_psd, negative rounding is clamped to 0.
/// The flip quotient is replaced by the mean of g″(σ₁), g″(σ₂) when σ₁ − σ₂ ≤ 1e-6 σ₁, where
/// it would lose its digits, so the Hessian stays finite and accurate at σ₁ = σ₂. Throws
/// NumericalError when σ₁ ≥ s̄.
DeformationGradientMatrix strain_limit_stress_derivative(const DeformationGradient& F,
                                                         const StrainLimitBand& band,
                                                         bool project_psd);

/// One triangle's κ_s Ā φ(F); +∞ beyond the limit.
double strain_limit_triangle_energy(const TrianglePositions& x, const MembraneRest& rest,
                                    const StrainLimitBand& band, double stiffness);

/// ∂/∂(x0, x1, x2) of strain_limit_triangle_energy: κ_s Ā Aᵀ vec(P) with P = ∂φ/∂F
/// (pull_back_stress).
TriangleVector strain_limit_triangle_gradient(const TrianglePositions& x, const MembraneRest& rest,
                                              const StrainLimitBand& band, double stiffness);

/// κ_s Ā Aᵀ (∂²φ/∂F²) A (pull_back_stress_derivative); PSD when projected.
TriangleMatrix strain_limit_triangle_hessian(const TrianglePositions& x, const MembraneRest& rest,
                                             const StrainLimitBand& band, double stiffness,
                                             bool project_psd);

/// The largest α ∈ [0, 1] with σ₁(x + α dx) < s̄ for this triangle, found to within 1e-12 in
/// α from below. σ₁ = ‖F‖₂ is a norm of F, which is affine in α, so σ₁(α) is convex: when
/// σ₁ < s̄ at α = 0 and α = 1 it is below on all of [0, 1] (α = 1 is returned), and otherwise
/// it crosses s̄ exactly once, which bisection brackets; the lower end, evaluated at the very
/// positions x + α dx a line search forms, is returned. Throws NumericalError when x itself
/// is not below the limit.
double strain_limit_feasible_step(const TrianglePositions& x, const TrianglePositions& dx,
                                  const MembraneRest& rest, double limit);

/// A starting κ_s for a membrane of stretch modulus E·h (N/m): E h δ². With it the barrier's
/// stress in the middle of the band, κ_s g′ ≈ 1.2 κ_s/δ, is of the order of the membrane
/// stress E h δ there, so the barrier neither stiffens the band from its start nor lets loads
/// walk through it; doubling (update_strain_limit_stiffness) takes over where loads are larger.
double initial_strain_limit_stiffness(double stretch_modulus, const StrainLimitBand& band);

/// Codim-IPC's update, once per Newton iteration: κ_s ← min(2κ_s, κ_max) when the smallest
/// slack s̄ − σ₁ over all triangles was below 1e-4 δ at the previous and at the current
/// iterate; κ_s unchanged otherwise. (Codim-IPC tests the slack triangle by triangle; the
/// minimum over triangles is the same test for the tightest one.)
double update_strain_limit_stiffness(double stiffness, double previous_min_slack, double min_slack,
                                     const StrainLimitBand& band, double max_stiffness);

/// The strain-limit energy of one shell inside a scene's global position vector x (size 3N):
/// the shell's local vertex i is global vertex vertex_offset + i.
class StrainLimitEnergy {
 public:
  /// Precomputes every triangle's rest data. Throws InputError for a band that is not
  /// 0 < ŝ < s̄ (finite), a stiffness that is not positive and finite, or a zero-area rest
  /// triangle.
  StrainLimitEnergy(const TriMesh& rest, const StrainLimitBand& band, double stiffness,
                    int vertex_offset = 0);

  /// Σ over triangles; +∞ if any triangle reaches the limit. Throws NumericalError for
  /// non-finite positions.
  [[nodiscard]] double value(const Eigen::VectorXd& x) const;
  /// g += ∇S(x). Throws NumericalError for non-finite positions or a triangle at the limit.
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// One 9×9 block per triangle inside the band (σ₁ > ŝ beyond rounding: unstretched
  /// triangles, σ₁ = 1 ± 1e-16 with the default ŝ = 1, are left out of the gradient and the
  /// Hessian), so the stencils change with the set of active triangles; PSD-projected unless
  /// project_psd is false.
  void hessian(const Eigen::VectorXd& x, ElementMatrices& out, bool project_psd = true) const;
  /// The largest α ∈ [0, 1] keeping every triangle strictly below the limit along x + α dx
  /// (strain_limit_feasible_step, minimized over triangles).
  [[nodiscard]] double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) const;
  /// min over triangles of s̄ − σ₁, the input of update_strain_limit_stiffness.
  [[nodiscard]] double min_slack(const Eigen::VectorXd& x) const;

  [[nodiscard]] double stiffness() const { return stiffness_; }
  void set_stiffness(double stiffness);
  [[nodiscard]] const StrainLimitBand& band() const { return band_; }
  [[nodiscard]] int triangle_count() const { return static_cast<int>(triangles_.size()); }

 private:
  /// The triangles inside the band and their stencils (3 global vertices each).
  struct ActiveSet {
    std::vector<std::size_t> triangles;
    std::vector<int> stencils;
  };
  [[nodiscard]] ActiveSet active_set(const Eigen::VectorXd& x) const;
  void check(const Eigen::VectorXd& x) const;

  StrainLimitBand band_;
  double stiffness_;
  int vertex_offset_;
  int vertex_count_;
  TriangleElements triangles_;
};

}  // namespace psq
