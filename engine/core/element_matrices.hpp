#pragma once
// Per-element dense Hessian blocks, the common currency between energy terms (which compute
// them, in parallel) and the sparse assembler (which sums them into a matrix over free DOFs).

#include <Eigen/Core>
#include <vector>

namespace psq {

/// A batch of elements that all touch `stencil_size` vertices. Element e touches
/// vertices[e*stencil_size ... +stencil_size) and its Hessian is the column-major
/// (3*stencil_size)^2 block at values[e*block_size() ...], ordered by (vertex, coordinate).
struct ElementMatrices {
  int stencil_size = 0;
  std::vector<int> vertices;
  std::vector<double> values;

  [[nodiscard]] int dofs_per_element() const { return 3 * stencil_size; }
  [[nodiscard]] std::size_t block_size() const {
    return static_cast<std::size_t>(dofs_per_element()) * dofs_per_element();
  }
  [[nodiscard]] std::size_t element_count() const {
    return stencil_size == 0 ? 0 : vertices.size() / stencil_size;
  }
  /// Sets the stencils and sizes `values` to match (values zeroed).
  void reset(int stencil, std::vector<int> stencil_vertices) {
    stencil_size = stencil;
    vertices = std::move(stencil_vertices);
    values.assign(element_count() * block_size(), 0.0);
  }
  /// Writable view of element e's Hessian block.
  Eigen::Map<Eigen::MatrixXd> block(std::size_t e) {
    return {values.data() + e * block_size(), dofs_per_element(), dofs_per_element()};
  }
  Eigen::Map<const Eigen::MatrixXd> block(std::size_t e) const {
    return {values.data() + e * block_size(), dofs_per_element(), dofs_per_element()};
  }
};

}  // namespace psq
