#pragma once
// Lagged, smoothed IPC friction (Li et al. 2020, "Incremental Potential Contact", §5).
//
// Each contact in reach at the lagged state xᵏ (the start of the step, then the result of
// each outer friction iteration) is frozen into a LaggedFrictionContact: its normal force
// magnitude λ, its tangent frame T and its closest-point weights w. Over the step from xᵗ,
// the contact's relative tangential displacement is
//   u(x) = Tᵀ Σᵢ wᵢ (xᵢ − xᵢᵗ),
// and its dissipation potential is D(x) = μ λ f₀(‖u‖) (friction_mollifier.hpp). With λ, T, w
// held fixed, u is linear in x and D is convex, so with Γ = Tᵀ (wᵀ ⊗ I₃) (2 × 12)
//   ∇D = μλ Γᵀ (f₁(y)/y) u,   ∇²D = μλ Γᵀ M Γ,   M = ∇²_u f₀(‖u‖) (PSD, no projection).
// The force on each side of a sliding contact (y ≥ ε) has magnitude exactly μλ and opposes
// u; below ε it is μλ f₁(y) ≈ 2μλ y/ε, a stiff spring holding the contact (static friction).
// The outer loop re-lags λ, T and w at the new solution until they settle (IPC's
// friction iterations); every term here is exact for the lagged quantities.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "engine/contact/barrier.hpp"
#include "engine/contact/tangent_basis.hpp"
#include "engine/core/element_matrices.hpp"

namespace psq {

/// The kind of a 4-vertex contact stencil: (p, t0, t1, t2) or (ea0, ea1, eb0, eb1).
enum class ContactKind { PointTriangle, EdgeEdge };

/// The normal force magnitude λ of a contact whose barrier potential is κ·c·b(d − ξ²) (c a
/// constant weight, e.g. the edge–edge mollifier's value, 1 otherwise). Its gradient with
/// respect to either side's closest point is κ c b′ ∇d with ∇d = ±2q, ‖q‖ = √d (the vector
/// between the closest points; every side's weights sum to 1), so
///   λ = 2 κ c √d |b′(d − ξ², ŝ)|
/// — IPC's λ = −κ ∂b/∂√d written for a barrier on squared distances (∂s/∂d = 1, see
/// BarrierBand). Zero outside the band. Throws NumericalError when d ≤ ξ².
double normal_force_magnitude(double squared_distance, const BarrierBand& band,
                              double barrier_stiffness, double barrier_weight = 1);

/// One contact with its friction data frozen at the lagged state.
struct LaggedFrictionContact {
  std::array<int, 4> vertices;  ///< global vertex indices of the stencil, in stencil order
  ContactFrame frame;           ///< T and w at the lagged state
  double friction_coefficient;  ///< μ ≥ 0
  double normal_force;          ///< λ ≥ 0 at the lagged state
};

/// Lags a contact at `lagged_positions` (global 3n vector): its frame for the sub-case its
/// distance takes there (point_triangle_frame / edge_edge_frame) and its normal force
/// (normal_force_magnitude of its squared distance there).
LaggedFrictionContact lag_friction_contact(ContactKind kind, const std::array<int, 4>& vertices,
                                           const Eigen::VectorXd& lagged_positions,
                                           const BarrierBand& band, double barrier_stiffness,
                                           double friction_coefficient, double barrier_weight = 1);

/// u = Tᵀ Σᵢ wᵢ Δxᵢ for the stencil's displacements over the step (columns).
Eigen::Vector2d tangential_displacement(const ContactFrame& frame,
                                        const StencilPositions& displacement);

/// D = μλ f₀(‖u‖) for one contact, from its stencil's displacements over the step.
double friction_dissipation(const LaggedFrictionContact& contact,
                            const StencilPositions& displacement, double slip_threshold);

/// friction_dissipation with its gradient and Hessian over the stencil (block (i, j) of the
/// Hessian is μλ wᵢ wⱼ T M Tᵀ; PSD).
StencilDerivatives<12> friction_dissipation_derivatives(const LaggedFrictionContact& contact,
                                                        const StencilPositions& displacement,
                                                        double slip_threshold);

/// The friction term D(x) = Σ μλ f₀(‖u‖) over a set of lagged contacts, for a global position
/// vector x (3n) and the step's start xᵗ.
class FrictionPotential {
 public:
  /// Keeps the contacts with μλ > 0 (μ = 0 or λ = 0 pairs exert no friction and are not
  /// stored). `slip_threshold` is ε = ε_v Δt (m). Throws InputError unless ε > 0 and finite,
  /// std::invalid_argument for a contact with a vertex outside `step_start`.
  FrictionPotential(const std::vector<LaggedFrictionContact>& contacts, Eigen::VectorXd step_start,
                    double slip_threshold);

  /// Σ over contacts. Throws NumericalError for non-finite positions.
  [[nodiscard]] double value(const Eigen::VectorXd& x) const;
  /// g += ∇D(x).
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// One 12×12 block per contact (stencil: its four vertices); PSD as computed (the lagged
  /// potential is convex), so there is nothing to project. Reuses out's storage when its
  /// stencils already match.
  void hessian(const Eigen::VectorXd& x, ElementMatrices& out) const;

  [[nodiscard]] int contact_count() const { return static_cast<int>(contacts_.size()); }
  [[nodiscard]] const std::vector<LaggedFrictionContact>& contacts() const { return contacts_; }

 private:
  [[nodiscard]] StencilPositions displacement(const Eigen::VectorXd& x, std::size_t c) const;
  /// friction_dissipation_derivatives of contact c at x.
  [[nodiscard]] StencilDerivatives<12> contact_derivatives(const Eigen::VectorXd& x,
                                                           std::size_t c) const;
  void check(const Eigen::VectorXd& x) const;

  std::vector<LaggedFrictionContact> contacts_;
  std::vector<int> stencils_;  ///< 4 global vertices per contact
  Eigen::VectorXd step_start_;
  double slip_threshold_;
};

}  // namespace psq
