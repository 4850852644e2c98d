#pragma once
// Sums element Hessian blocks into one sparse matrix over the free degrees of freedom. The
// sparsity pattern and the scatter map are built once and reused while the stencils stay the
// same, so a Newton iteration only pays for one tight scatter loop.

#include <Eigen/SparseCore>
#include <cstddef>
#include <vector>

#include "engine/solver/dof_map.hpp"
#include "engine/solver/objective.hpp"

namespace psq {

/// Assembles K = diag(d) + Σₑ Pₑᵀ Hₑ Pₑ restricted to the free DOFs, where Pₑ picks element e's
/// DOFs, and stores its upper triangle (row ≤ column) in compressed-column form: the form
/// CHOLMOD factorizes fastest (stype = 1).
///
/// Element blocks must be symmetric; only their upper triangles are read. The DofMap must
/// number free DOFs in increasing order of their full index (DofMap does).
class SparseAssembler {
 public:
  /// Sums `blocks` into matrix(). The pattern and scatter map are rebuilt only when the
  /// stencils (batch count, stencil sizes, vertex lists) or the DOF map differ from the previous
  /// call; checking costs one comparison of the vertex lists.
  /// @return true when the sparsity pattern differs from the previous call's (always on the
  ///   first call), i.e. when a symbolic factorization must be redone.
  bool assemble(const HessianBlocks& blocks, const DofMap& dofs);

  /// The assembled upper triangle, free_size × free_size.
  [[nodiscard]] const Eigen::SparseMatrix<double>& matrix() const { return matrix_; }
  /// How many times the pattern and scatter map have been built.
  [[nodiscard]] std::size_t rebuild_count() const { return rebuild_count_; }

 private:
  /// The stencil of one batch as seen at the last rebuild, and where its entries go.
  struct BatchMap {
    int stencil_size = 0;
    std::vector<int> vertices;
    /// Per element, per upper-triangle entry (i ≤ j, column by column): the value slot, or −1
    /// when either DOF is fixed.
    std::vector<int> slots;
    /// Entries (i < j) whose two DOFs coincide (a vertex listed twice): their mirror (j, i)
    /// also lands on the diagonal, so it is added separately. Pairs of (value index, slot).
    std::vector<std::pair<std::size_t, int>> mirrored;
  };

  [[nodiscard]] bool stencils_match(const HessianBlocks& blocks, const DofMap& dofs) const;
  [[nodiscard]] bool dofs_match(const DofMap& dofs) const;
  [[nodiscard]] bool batch_matches(std::size_t b, const ElementMatrices& batch) const;
  /// Builds the pattern; returns true when it differs from the current one.
  bool rebuild_pattern(const HessianBlocks& blocks, const DofMap& dofs);
  /// Rebuilds the scatter maps; with `pattern_changed` false and the same DOF map, only those
  /// of batches whose stencils changed (their slots in an unchanged pattern are the same).
  void rebuild_scatter_map(const HessianBlocks& blocks, const DofMap& dofs, bool pattern_changed);
  /// One batch's slots in the current pattern and DOF numbering (reduced_).
  void rebuild_batch_map(const ElementMatrices& batch, BatchMap& map) const;
  void scatter(const HessianBlocks& blocks);

  Eigen::SparseMatrix<double> matrix_;
  std::vector<int> reduced_;        ///< DofMap::reduced of every full DOF at the last rebuild
  std::vector<int> diagonal_slots_; ///< per full DOF: slot of its diagonal entry, −1 if fixed
  std::vector<BatchMap> batches_;
  std::size_t rebuild_count_ = 0;
};

}  // namespace psq
