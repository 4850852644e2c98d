#pragma once
// The Newton tolerance of a scene and the check that it still means convergence at the scene's
// pseudo time step (docs/stress.md, "Huge and tiny pseudo time steps").

#include "engine/scene/scene.hpp"

namespace psq {

/// A converged step may still move a vertex by tolerance·Δt; more than this fraction of the
/// scene's bounding-box diagonal is no answer. With the default tolerance (1e-4 × the diagonal
/// per second) it allows Δt up to 10 s; the library's Δt = 0.04 s moves at most 4e-6 of it.
/// Measured (jobs/sweeps/stress-time-step.toml): at Δt = 1000 s the drape's frames "converged"
/// after 5 iterations 0.83 m from the equilibrium the same scene reaches at Δt = 0.04 s.
inline constexpr double kLargestConvergedMoveFraction = 1e-3;

/// The scene's tolerance on ‖Δx‖∞/Δt [m/s]: solver.tolerance, or 1e-4 × `diagonal` (the rest
/// state's bounding-box diagonal) per second.
double solver_tolerance(const Scene& scene, double diagonal);

/// Throws InputError naming time.step and solver.tolerance when tolerance·Δt exceeds
/// kLargestConvergedMoveFraction × `diagonal`.
void check_convergence_resolution(const Scene& scene, double diagonal);

}  // namespace psq
