#pragma once
// IPC's log barrier on squared distances (b, b′, b″ of engine/core/log_barrier.hpp), its
// thickness offset, and the adaptive barrier stiffness κ (Li et al. 2020, "Incremental
// Potential Contact"; the κ rules follow ipc-toolkit's initial_barrier_stiffness and
// update_barrier_stiffness).
//
// Convention: like every distance in engine/contact, the barrier works on SQUARED distances.
// Its argument s and activation ŝ are squared lengths (m²); the activation distance d̂ and the
// thickness ξ of BarrierBand are unsigned lengths (m). With ξ = 0, s = d and ŝ = d̂².

#include <Eigen/Core>

#include "engine/contact/distance_type.hpp"
#include "engine/core/log_barrier.hpp"

namespace psq {

/// Where the barrier acts, in unsigned distances: it is infinite at the thickness ξ and zero
/// from ξ + d̂ on. The thickness enters as an offset of the squared distance d,
///   s = d − ξ²,   ŝ = (ξ + d̂)² − ξ² = d̂ (2ξ + d̂),
/// rather than as (√d − ξ)²: s stays a polynomial in the positions (no square root, smooth
/// wherever d is), and ∂s/∂d = 1, so b′ and b″ are also the derivatives with respect to d.
/// Near the offset surface s ≈ 2ξ (√d − ξ), so the barrier still blows up like the log of
/// the gap √d − ξ.
struct BarrierBand {
  double activation_distance = 0;  ///< d̂ > 0 (m)
  double thickness = 0;            ///< ξ ≥ 0 (m)

  /// s = d − ξ² for a squared distance d.
  [[nodiscard]] double barrier_argument(double squared_distance) const {
    return squared_distance - thickness * thickness;
  }
  /// ŝ = d̂ (2ξ + d̂).
  [[nodiscard]] double barrier_activation() const {
    return activation_distance * (2 * thickness + activation_distance);
  }
};

/// b(d(x) − ξ²) for the squared distance of a point–triangle or edge–edge stencil, with its
/// derivatives (chain_rule):
///   ∇ = b′ ∇d,   ∇² = b″ ∇d ∇dᵀ + b′ ∇²d.
/// Not scaled by κ. Zero outside the band. Throws NumericalError when d ≤ ξ² (penetration:
/// a state the line search must never accept).
StencilDerivatives<12> barrier_of_distance(const StencilDerivatives<12>& distance,
                                           const BarrierBand& band);

/// The barrier stiffness κ and its upper bound.
struct BarrierStiffness {
  double value = 0;  ///< κ
  double max = 0;    ///< κ_max, never exceeded by update_barrier_stiffness
};

/// IPC's initial barrier stiffness. The smallest useful κ makes the barrier's curvature across
/// a tiny gap g₀ = 1e-8 l (l the bounding-box diagonal; g₀ at most d̂/2) as stiff as
/// `min_stiffness_scale` times the inertia:
///   κ_min = min_stiffness_scale · m̄ / (4 d₀ b″(d₀ − ξ², ŝ)),   d₀ = (ξ + g₀)²,
///   κ_max = 100 κ_min,
/// where 4 d₀ b″ is IPC's estimate of ∂²b/∂g² through the squared distance (it drops the
/// 2 b′ term). Between those bounds κ is the least-squares balance of the energy and barrier
/// gradients at the start state, κ = −∇E·∇B / ‖∇B‖², the κ that makes ‖∇E + κ∇B‖ smallest;
/// κ_min when no pair is active (∇B = 0).
/// `average_mass`: the mean vertex mass as weighted in the objective's inertia term (m̄/Δt²
/// for E = ‖x − xᵗ‖²_M/(2Δt²) + …). `barrier_gradient`: ∇ of Σ b over the pairs, κ = 1.
/// Throws NumericalError unless l, d̂ and m̄ are positive and finite.
BarrierStiffness initial_barrier_stiffness(double bbox_diagonal, const BarrierBand& band,
                                           double average_mass,
                                           const Eigen::VectorXd& energy_gradient,
                                           const Eigen::VectorXd& barrier_gradient,
                                           double min_stiffness_scale = 1e11);

/// IPC's stiffness update between Newton iterations, made to catch up with the contact force
/// where the CCD creeps. IPC doubles κ when the smallest gap g = √d − ξ over all pairs was
/// already below ε_g = gap_scale · l (l the bounding-box diagonal) and has decreased again.
/// Doubling is too slow where a stiff structure presses a contact far below ε_g and holds it
/// there (a crushed can's rim against the plate): the CCD then cuts every Newton step to a
/// sliver of its length until κ has caught up. So when the caller reports
/// that the CCD cut the steps (`steps_cut_by_ccd`) and the gap has stalled below ε_g (it
/// changed by less than a factor 2 since the last update), κ grows by the ratio of the
/// barrier's push at g to its push at ε_g, the κ that would hold the same force at ε_g:
///   κ ← min(f κ, κ_max),   f = max(2 [IPC's rule], |∂b/∂g|(g) / |∂b/∂g|(ε_g) [cut, stalled]).
/// A small gap alone is no evidence of a large force (a pair a refinement just placed sits
/// close without pressing), and a gap still falling fast may be a transient of the iteration,
/// hence the CCD's report and the stall.
/// `previous_min_distance` and `min_distance` are squared distances (+∞ when no pair is in
/// reach). With ξ = 0, ε_g² on squared distances is ipc-toolkit's threshold.
BarrierStiffness update_barrier_stiffness(const BarrierStiffness& stiffness,
                                          double previous_min_distance, double min_distance,
                                          double bbox_diagonal, const BarrierBand& band,
                                          double gap_scale = 1e-9, bool steps_cut_by_ccd = false);

}  // namespace psq
