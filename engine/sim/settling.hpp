#pragma once
// The settling schedule: quasistatic steps at one frame with the loading held (xᵗ ← x each
// step) and a growing pseudo time step, until the state is a static equilibrium. A frame's answer
// (direct or the finest level of a progressive solve) and a progressive level at its refine frame
// are settled by it.
//
// A fixed Δt stalls in soft directions: each step moves them by their stiffness over M/Δt², so
// steps get small long before the equilibrium is reached. Growing Δt fades the inertia-like
// term; at the largest step (Δt·4⁶) it weighs 1/4⁶² ≈ 6e-8 of the first, and a step there is a
// Newton solve of the static problem with a vanishing regularization.

namespace psq {

/// Growth index of the largest settling time step.
inline constexpr int kSettlingGrowthSteps = 6;

/// Pseudo time step of settling growth index k = 0, 1, …: Δt·4^k, at most Δt·4^kSettlingGrowthSteps.
double settling_time_step(double time_step, int growth);

/// Settling ends at the first step taken at the largest time step whose change ‖x − xᵗ‖∞/Δt is
/// below the tolerance: only then is a small change a small distance to the equilibrium.
bool settling_done(int growth, double change, double tolerance);

/// The growth index after a step at index `growth`: one more, or kSettlingGrowthSteps at once
/// when that step had nothing to solve (`converged_at_start`: no Newton iteration needed) —
/// the inertia-like term no longer held anything back, and growing Δt 4× at a time would only
/// cost one more Hessian and factorization per step.
int next_settling_growth(int growth, bool converged_at_start);

}  // namespace psq
