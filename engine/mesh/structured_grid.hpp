#pragma once
// The connectivity of structured grids (private to engine/mesh): the sheet and the panels of
// cylinders and spheres are each a grid of (u, v) cells mapped onto their surface.

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Vertex (i, j) of a grid of nu × nv cells: index j·(columns) + i, where a grid closed in u
/// (its column nu is column 0) has nu columns and an open one nu + 1.
struct GridIndexing {
  int nu = 1, nv = 1;
  bool closed_u = false;
  [[nodiscard]] int columns() const { return closed_u ? nu : nu + 1; }
  [[nodiscard]] int vertex_count() const { return columns() * (nv + 1); }
  [[nodiscard]] int id(int i, int j) const { return j * columns() + (closed_u ? i % nu : i); }
};

/// Two triangles per cell, split along a diagonal whose direction alternates like a
/// checkerboard ((i + j) even: from (i, j) to (i + 1, j + 1)), wound so that the normal is
/// ∂u × ∂v. One diagonal direction throughout would couple bending to twist in hinge models (a
/// cantilever strip ends up ~30% too soft); alternating them cancels that coupling. A closed
/// grid needs an even nu for the pattern to continue across its seam.
Eigen::MatrixXi checkerboard_triangles(const GridIndexing& grid);

/// Rounds a cell count up to a multiple of `multiple` (at least one multiple).
int round_up_cells(double cells, int multiple);

}  // namespace psq
