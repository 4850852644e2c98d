#pragma once
// IPC's smoothed friction law (Li et al. 2020, "Incremental Potential Contact", §5.1). Coulomb
// friction opposes sliding with a force of magnitude μλ whatever the slip; IPC replaces the
// jump at zero slip by a smooth ramp, so that below the slip threshold ε the friction force
// grows linearly like a stiff spring (static friction, up to a creep of order ε) and above it
// is exactly μλ (dynamic friction). With y = ‖u‖ the magnitude of a contact's tangential
// displacement over the step, the dissipation potential is μλ f₀(y), where
//   f₀(y) = −y³/(3ε²) + y²/ε + ε/3   for y < ε,     f₀(y) = y   for y ≥ ε,
//   f₁(y) = f₀′(y) = 2y/ε − y²/ε²    for y < ε,     f₁(y) = 1   for y ≥ ε.
// f₀ is C² (f₁′ = 2(ε − y)/ε² vanishes at ε), nondecreasing and convex on [0, ∞), so
// f₀(‖u‖) is a convex function of u. IPC writes ε = ε_v h (a velocity threshold times the
// time step); here ε is that product, a length (m): the slip below which a contact sticks.

#include <Eigen/Core>

namespace psq {

/// f₀(y) above, for y ≥ 0 and ε > 0.
double friction_mollifier(double y, double slip_threshold);

/// f₁(y) = f₀′(y): the friction force as a fraction of μλ, in [0, 1].
double friction_mollifier_derivative(double y, double slip_threshold);

/// f₁(y)/y: 2/ε − y/ε² below ε (2/ε at y = 0, where f₁(y)/y stays finite), 1/y above.
double friction_mollifier_derivative_over_norm(double y, double slip_threshold);

/// f₁′(y) = f₀″(y): 2(ε − y)/ε² below ε, 0 above.
double friction_mollifier_second_derivative(double y, double slip_threshold);

/// ∇_u f₀(‖u‖) = (f₁(y)/y) u, zero at u = 0.
Eigen::Vector2d friction_mollifier_gradient(const Eigen::Vector2d& u, double slip_threshold);

/// ∇²_u f₀(‖u‖) in the closed form of its eigensystem: with û = u/y,
///   M = (f₁(y)/y) (I − û ûᵀ) + f₁′(y) û ûᵀ,
/// which is (2/ε) I at u = 0. IPC projects this 2×2 block to PSD by clamping the eigenvalue
/// along û, f₁′(y), at zero; for this mollifier f₁′ = 2(ε − y)/ε² ≥ 0 and f₁/y > 0 (also in
/// floating point), so M is PSD as it stands and the projection is the identity.
Eigen::Matrix2d friction_mollifier_hessian(const Eigen::Vector2d& u, double slip_threshold);

}  // namespace psq
