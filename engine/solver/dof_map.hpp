#pragma once
// Which degrees of freedom the solver moves. Pinned (Dirichlet) DOFs are removed from the
// linear systems rather than penalized, so they hold their prescribed values exactly. A vertex
// may have some of its three DOFs fixed and the others free (a pin of chosen components).

#include <Eigen/Core>
#include <vector>

namespace psq {

class DofMap {
 public:
  /// All 3n DOFs free, then all three of each of `pinned_vertices` fixed.
  DofMap(Eigen::Index vertex_count, const std::vector<int>& pinned_vertices);
  /// Per DOF (3n entries, x y z of each vertex in turn), whether it is fixed.
  explicit DofMap(const std::vector<bool>& fixed_dofs);

  [[nodiscard]] Eigen::Index full_size() const { return static_cast<Eigen::Index>(reduced_.size()); }
  [[nodiscard]] Eigen::Index free_size() const { return free_count_; }
  /// Index among the free DOFs, or −1 when the DOF is fixed.
  [[nodiscard]] int reduced(Eigen::Index full_dof) const { return reduced_[full_dof]; }
  /// Entries of a full vector at the free DOFs.
  [[nodiscard]] Eigen::VectorXd restrict(const Eigen::VectorXd& full) const;
  /// A full vector with `reduced_values` at the free DOFs and zero at the fixed ones.
  [[nodiscard]] Eigen::VectorXd extend(const Eigen::VectorXd& reduced_values) const;
  /// Per vertex, whether all three of its DOFs are fixed. A vertex with a free component still
  /// moves, so a term that treats fixed vertices as constants (the contact Hessian's PSD
  /// projection over the moving points, HessianBlocks::fixed_vertices) must count it as moving.
  [[nodiscard]] std::vector<bool> fixed_vertices() const;

 private:
  /// Numbers the free DOFs (those not marked −1 in reduced_) in increasing order.
  void number_free_dofs();

  std::vector<int> reduced_;
  Eigen::Index free_count_ = 0;
};

}  // namespace psq
