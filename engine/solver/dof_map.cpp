#include "engine/solver/dof_map.hpp"

#include <stdexcept>

namespace psq {

DofMap::DofMap(Eigen::Index vertex_count, const std::vector<int>& pinned_vertices)
    : reduced_(static_cast<std::size_t>(3 * vertex_count), 0) {
  for (int v : pinned_vertices)
    for (int c = 0; c < 3; ++c) reduced_[3 * v + c] = -1;
  number_free_dofs();
}

DofMap::DofMap(const std::vector<bool>& fixed_dofs) : reduced_(fixed_dofs.size(), 0) {
  if (fixed_dofs.size() % 3 != 0)
    throw std::invalid_argument("DofMap: fixed_dofs needs three entries per vertex");
  for (std::size_t i = 0; i < fixed_dofs.size(); ++i)
    if (fixed_dofs[i]) reduced_[i] = -1;
  number_free_dofs();
}

void DofMap::number_free_dofs() {
  for (int& r : reduced_)
    if (r == 0) r = static_cast<int>(free_count_++);
}

Eigen::VectorXd DofMap::restrict(const Eigen::VectorXd& full) const {
  Eigen::VectorXd out(free_count_);
  for (std::size_t i = 0; i < reduced_.size(); ++i)
    if (reduced_[i] >= 0) out[reduced_[i]] = full[static_cast<Eigen::Index>(i)];
  return out;
}

Eigen::VectorXd DofMap::extend(const Eigen::VectorXd& reduced_values) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(full_size());
  for (std::size_t i = 0; i < reduced_.size(); ++i)
    if (reduced_[i] >= 0) out[static_cast<Eigen::Index>(i)] = reduced_values[reduced_[i]];
  return out;
}

std::vector<bool> DofMap::fixed_vertices() const {
  std::vector<bool> fixed(reduced_.size() / 3);
  for (std::size_t v = 0; v < fixed.size(); ++v)
    fixed[v] = reduced_[3 * v] < 0 && reduced_[3 * v + 1] < 0 && reduced_[3 * v + 2] < 0;
  return fixed;
}

}  // namespace psq
