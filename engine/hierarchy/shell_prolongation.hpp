#pragma once
// Shell prolongation (paper §4.3, eqs. 4–9): maps positions of a coarse level to target
// points (the vertices of the next finer level, or of the finest level) as
//   x_i = Σ_k b_ik x_{t_i,k} + n_{t_i}(x) γ_i + R(F_{t_i}(x)) t_i,
// the intrinsic anchor (barycentric interpolation in the containing triangle t_i) plus the
// rest-shape offset split into a normal part γ_i (along the deformed triangle normal) and an
// in-plane part t_i ∈ R² (turned by the rotation factor of the triangle's deformation
// gradient). Rest shapes are reproduced exactly.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/hierarchy/triangle_frame.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

class ShellProlongation {
 public:
  /// `coarse_rest`: the coarse level's rest mesh; `locations[i]`: where target i lies on it;
  /// `target_rest`: the targets' rest positions (one row per location).
  ShellProlongation(const TriMesh& coarse_rest, std::vector<SurfaceLocation> locations,
                    const Positions& target_rest);

  [[nodiscard]] int target_count() const;
  [[nodiscard]] int coarse_vertex_count() const;

  /// P(x): the prolonged target positions.
  [[nodiscard]] Positions apply(const Positions& coarse) const;
  /// U: the linear (intrinsic) part as a 3m×3n matrix acting on flat positions.
  [[nodiscard]] const Eigen::SparseMatrix<double>& linear_part() const;
  /// a(x): the nonlinear offsets n(x)γ + R(F(x))t, one row per target.
  [[nodiscard]] Positions offsets(const Positions& coarse) const;
  /// (∂P/∂x)ᵀ g for a flat target vector g (3m): the exact chain rule through the offsets.
  [[nodiscard]] Eigen::VectorXd apply_jacobian_transpose(const Positions& coarse,
                                                         const Eigen::VectorXd& g) const;

  /// Where each target lies on the coarse level.
  [[nodiscard]] const std::vector<SurfaceLocation>& locations() const { return locations_; }

 private:
  /// The deformed frame of every coarse triangle that holds a target (used_triangles_ order).
  [[nodiscard]] std::vector<DeformedTriangleFrame> deformed_frames(const Positions& coarse) const;
  void check_coarse(const Positions& coarse) const;

  int coarse_vertex_count_ = 0;
  Triangles triangles_;
  std::vector<SurfaceLocation> locations_;
  std::vector<double> normal_offsets_;             ///< γ_i
  std::vector<Eigen::Vector2d> in_plane_offsets_;  ///< t_i
  std::vector<int> used_triangles_;                ///< coarse triangles holding a target
  std::vector<int> slot_of_triangle_;              ///< index into used_triangles_, or -1
  std::vector<Eigen::Matrix2d> b_inverse_;         ///< per used triangle
  std::vector<int> target_start_, targets_;        ///< CSR: targets per used triangle
  std::vector<int> corner_start_, corners_;        ///< CSR: 3·slot + corner per coarse vertex
  Eigen::SparseMatrix<double> linear_part_;
};

/// The direct prolongation P^l (paper §4.3.1): level `level` → the finest level, anchored
/// by HierarchyLevel::finest with offsets to the finest rest mesh. Throws InputError for a
/// level outside [0, L].
ShellProlongation direct_prolongation(const MeshHierarchy& hierarchy, int level);

/// The per-level prolongation P^l_{l+1}: level `level` → level `level` + 1, anchored by
/// HierarchyLevel::next_finer. Throws InputError for a level outside [0, L − 1].
ShellProlongation level_prolongation(const MeshHierarchy& hierarchy, int level);

}  // namespace psq
