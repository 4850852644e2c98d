#include "engine/mesh/structured_grid.hpp"

#include <cmath>
#include <stdexcept>

namespace psq {

Eigen::MatrixXi checkerboard_triangles(const GridIndexing& grid) {
  if (grid.closed_u && grid.nu % 2 != 0)
    throw std::invalid_argument("checkerboard_triangles: a closed grid needs an even nu");
  Eigen::MatrixXi triangles(2 * grid.nu * grid.nv, 3);
  int f = 0;
  for (int j = 0; j < grid.nv; ++j)
    for (int i = 0; i < grid.nu; ++i) {
      const int a = grid.id(i, j), b = grid.id(i + 1, j);
      const int c = grid.id(i + 1, j + 1), d = grid.id(i, j + 1);
      if ((i + j) % 2 == 0) {
        triangles.row(f++) << a, b, c;
        triangles.row(f++) << a, c, d;
      } else {
        triangles.row(f++) << a, b, d;
        triangles.row(f++) << b, c, d;
      }
    }
  return triangles;
}

int round_up_cells(double cells, int multiple) {
  // The tolerance keeps an exact quotient (width 1, edge 0.1) from rounding up to the next one.
  const int whole = std::max(1, static_cast<int>(std::ceil(cells - 1e-9)));
  return ((whole + multiple - 1) / multiple) * multiple;
}

}  // namespace psq
