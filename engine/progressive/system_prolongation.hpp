#pragma once
// Prolongation of a whole multi-shell system: the shells are concatenated into one vertex array
// (ShellSystem), and each shell is prolonged by its own ShellProlongation on its blocks of the
// coarse and target arrays.

#include <Eigen/Core>
#include <vector>

#include "engine/hierarchy/shell_prolongation.hpp"

namespace psq {

/// The identity as a ShellProlongation: every vertex of `rest` located at its own corner of a
/// triangle that holds it. Used for shells whose hierarchy has fewer levels than the system's.
ShellProlongation identity_prolongation(const TriMesh& rest);

class SystemProlongation {
 public:
  /// One map per shell, in the shells' order in the concatenated arrays.
  explicit SystemProlongation(std::vector<ShellProlongation> shells);

  [[nodiscard]] Eigen::Index coarse_size() const { return 3 * Eigen::Index(coarse_vertices_); }
  [[nodiscard]] Eigen::Index target_size() const { return 3 * Eigen::Index(target_vertices_); }

  /// P(x) for flat coarse positions x (3n): flat target positions (3m).
  [[nodiscard]] Eigen::VectorXd apply(const Eigen::VectorXd& coarse) const;
  /// Uᵀg: the transpose of the linear (intrinsic) part, offsets held (paper eq. 10).
  [[nodiscard]] Eigen::VectorXd apply_linear_transpose(const Eigen::VectorXd& g) const;
  /// (∂P/∂x)ᵀg: the exact chain rule through the offsets.
  [[nodiscard]] Eigen::VectorXd apply_jacobian_transpose(const Eigen::VectorXd& coarse,
                                                         const Eigen::VectorXd& g) const;

 private:
  struct Block {
    ShellProlongation map;
    int first_coarse;  ///< first vertex of this shell in the coarse array
    int first_target;  ///< first vertex of this shell in the target array
  };
  std::vector<Block> blocks_;
  int coarse_vertices_ = 0;
  int target_vertices_ = 0;
};

}  // namespace psq
