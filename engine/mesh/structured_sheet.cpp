#include <cmath>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_checks.hpp"
#include "engine/mesh/structured_grid.hpp"

namespace psq {

TriMesh make_structured_sheet(const SheetGenerator& spec) {
  require_positive("sheet", "width", spec.width);
  require_positive("sheet", "height", spec.height);
  require_positive("sheet", "edge_length", spec.edge_length);
  if (!spec.holes.empty())
    throw InputError("sheet: holes need an unstructured sheet (structured = false)");
  const GridIndexing grid{round_up_cells(spec.width / spec.edge_length, 1),
                          round_up_cells(spec.height / spec.edge_length, 1), false};
  TriMesh mesh;
  mesh.vertices.resize(grid.vertex_count(), 3);
  for (int j = 0; j <= grid.nv; ++j)
    for (int i = 0; i <= grid.nu; ++i)
      mesh.vertices.row(grid.id(i, j)) << -0.5 * spec.width + spec.width * i / grid.nu,
          -0.5 * spec.height + spec.height * j / grid.nv, 0.0;
  mesh.triangles = checkerboard_triangles(grid);
  return mesh;
}

}  // namespace psq
