#include "engine/progressive/local_solve.hpp"

namespace psq {

DofMap movable_vertex_dofs(const ShellSystem& system, const std::vector<bool>& movable) {
  std::vector<bool> fixed = system.fixed_dofs();
  for (std::size_t v = 0; v < movable.size(); ++v)
    if (!movable[v]) fixed[3 * v] = fixed[3 * v + 1] = fixed[3 * v + 2] = true;
  return DofMap(fixed);
}

void balance_barrier_stiffness(ContactTerm& contact, const Eigen::VectorXd& x,
                               const Eigen::VectorXd& gradient, const DofMap& dofs) {
  std::vector<bool> free(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) free[i] = dofs.reduced(i) >= 0;
  // IPC's κ_min scales with the Hessian's diagonal, which it takes as m̄/Δt²; here it is one.
  contact.initialize_stiffness(x, gradient, free, 1.0 / contact.average_mass());
}

}  // namespace psq
