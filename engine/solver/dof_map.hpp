#pragma once
// Which degrees of freedom the solver moves. Pinned (Dirichlet) vertices are removed from the
// linear systems rather than penalized, so they hold their prescribed positions exactly.

#include <Eigen/Core>
#include <vector>

namespace psq {

class DofMap {
 public:
  /// All 3n DOFs free, then those of `pinned_vertices` fixed.
  DofMap(Eigen::Index vertex_count, const std::vector<int>& pinned_vertices);

  [[nodiscard]] Eigen::Index full_size() const { return static_cast<Eigen::Index>(reduced_.size()); }
  [[nodiscard]] Eigen::Index free_size() const { return free_count_; }
  /// Index among the free DOFs, or −1 when the DOF is fixed.
  [[nodiscard]] int reduced(Eigen::Index full_dof) const { return reduced_[full_dof]; }
  /// Entries of a full vector at the free DOFs.
  [[nodiscard]] Eigen::VectorXd restrict(const Eigen::VectorXd& full) const;
  /// A full vector with `reduced_values` at the free DOFs and zero at the fixed ones.
  [[nodiscard]] Eigen::VectorXd extend(const Eigen::VectorXd& reduced_values) const;
  /// Per vertex, whether it is fixed (pinned vertices are fixed whole).
  [[nodiscard]] std::vector<bool> fixed_vertices() const;

 private:
  std::vector<int> reduced_;
  Eigen::Index free_count_ = 0;
};

}  // namespace psq
