#pragma once
// Prolongation of a whole multi-shell system: the shells are concatenated into one vertex array
// (ShellSystem), and each shell (and each collider with a hierarchy, paper §4.6) is prolonged by
// its own ShellProlongation on its blocks of the coarse and target arrays. Colliders without
// hierarchies keep their mesh at every level: their vertices follow in both arrays and are
// copied.

#include <Eigen/Core>
#include <vector>

#include "engine/hierarchy/shell_prolongation.hpp"

namespace psq {

/// The identity as a ShellProlongation: every vertex of `rest` located at its own corner of a
/// triangle that holds it. Used for shells whose hierarchy has fewer levels than the system's.
ShellProlongation identity_prolongation(const TriMesh& rest);

class SystemProlongation {
 public:
  /// One map per mesh (shells, then colliders with hierarchies), in their order in the
  /// concatenated arrays, then `collider_vertices` copied vertices.
  explicit SystemProlongation(std::vector<ShellProlongation> shells, int collider_vertices = 0);

  [[nodiscard]] Eigen::Index coarse_size() const { return 3 * Eigen::Index(coarse_vertices_); }
  [[nodiscard]] Eigen::Index target_size() const { return 3 * Eigen::Index(target_vertices_); }

  /// P(x) for flat coarse positions x (3n): flat target positions (3m).
  [[nodiscard]] Eigen::VectorXd apply(const Eigen::VectorXd& coarse) const;
  /// Ux: the linear (intrinsic) part alone, each target at its anchor on the coarse surface.
  [[nodiscard]] Eigen::VectorXd apply_linear(const Eigen::VectorXd& coarse) const;
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
  /// Copies the collider rows of `from` (after its first `from_first` vertices) into those of
  /// `to` (after `to_first`).
  void copy_colliders(const Eigen::VectorXd& from, int from_first, Eigen::VectorXd& to,
                      int to_first) const;

  std::vector<Block> blocks_;
  int collider_vertices_ = 0;
  int shell_coarse_vertices_ = 0;  ///< the colliders' first vertex in the coarse array
  int shell_target_vertices_ = 0;  ///< the colliders' first vertex in the target array
  int coarse_vertices_ = 0;
  int target_vertices_ = 0;
};

}  // namespace psq
