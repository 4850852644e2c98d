#include "engine/progressive/local_solve.hpp"

namespace psq {

DofMap movable_vertex_dofs(const ShellSystem& system, const std::vector<bool>& movable) {
  std::vector<bool> fixed(movable.size());
  for (std::size_t v = 0; v < movable.size(); ++v) fixed[v] = !movable[v];
  for (const PinnedVertex& pin : system.pinned()) fixed[pin.vertex] = true;
  std::vector<int> fixed_vertices;
  for (std::size_t v = 0; v < fixed.size(); ++v)
    if (fixed[v]) fixed_vertices.push_back(static_cast<int>(v));
  return DofMap(static_cast<Eigen::Index>(movable.size()), fixed_vertices);
}

void balance_barrier_stiffness(ContactTerm& contact, const Eigen::VectorXd& x,
                               const Eigen::VectorXd& gradient, const DofMap& dofs) {
  std::vector<bool> free(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) free[i] = dofs.reduced(i) >= 0;
  // IPC's κ_min scales with the Hessian's diagonal, which it takes as m̄/Δt²; here it is one.
  contact.initialize_stiffness(x, gradient, free, 1.0 / contact.average_mass());
}

}  // namespace psq
