#pragma once
// Pieces shared by the refinement's local solves (target_relaxation.hpp,
// strain_limit_correction.hpp): Newton over a few of a level's vertices with the scene's
// barrier, on objectives whose Hessian is of order one per DOF rather than m/Δt².

#include <Eigen/Core>
#include <vector>

#include "engine/sim/contact_term.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/solver/dof_map.hpp"

namespace psq {

/// The DOFs of the `movable` vertices of `system` free, except those its pins fix; every DOF of
/// the other vertices fixed.
DofMap movable_vertex_dofs(const ShellSystem& system, const std::vector<bool>& movable);

/// Sets the contact term's κ by IPC's initial rule at x, balancing the barrier against
/// `gradient` (the rest of the objective's gradient) over the free DOFs of `dofs`.
void balance_barrier_stiffness(ContactTerm& contact, const Eigen::VectorXd& x,
                               const Eigen::VectorXd& gradient, const DofMap& dofs);

}  // namespace psq
