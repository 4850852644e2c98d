#pragma once
// The scene's probes read at a state: mean displacements of vertex selections and reactions of
// pinned sets ([[shell.probe]], docs/scene-format.md).
//
// The reaction of a pinned set. Let Π(x) = Ψ(x) + B(x) − f·x be the static potential: the
// elastic energies Ψ, the barriers B (contact, strain limits) and the external force f, without
// the inertia-like term of a step. A pin holds DOF i by a force r_i that the support exerts on
// it; the DOF is at rest when the forces on it cancel: −∂Π/∂x_i + r_i = 0, so r_i = g_i, the
// static gradient. The probe records R = −Σ g_i e_c(i) over the DOFs the set fixes (e_c the unit
// vector of the DOF's component): the force the set's vertices exert on their support, the load
// the support carries. Σ_i g_i over every DOF of the system is −Σ f, since Ψ and B are invariant
// under translation; at an equilibrium the free DOFs' g_i vanish, so the reactions of all pinned
// sets, and the forces on the colliders (whose vertices are pinned too), add up to the total
// applied force: a cantilever's clamp carries its tip load (R = P), a hanging sheet's pin its
// weight (R = m g, pointing down). Lagged friction is not part of Π here (it is a term of the
// frame's solve only), so with friction that balance holds without it.

#include <string>
#include <vector>

#include "engine/sim/shell_system.hpp"

namespace psq {

/// One probe's value at one state: a mean displacement [m] or a reaction [N].
struct ProbeReading {
  std::string name;
  ProbeKind kind = ProbeKind::displacement;
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
};

/// Every probe of `system` at positions x, whose static gradient ∇Π(x) is `static_gradient`.
std::vector<ProbeReading> read_probes(const ShellSystem& system, const Eigen::VectorXd& x,
                                      const Eigen::VectorXd& static_gradient);

}  // namespace psq
