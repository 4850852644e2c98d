#include <cmath>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_checks.hpp"

namespace psq {

TriMesh make_structured_sheet(const SheetGenerator& spec) {
  require_positive("sheet", "width", spec.width);
  require_positive("sheet", "height", spec.height);
  require_positive("sheet", "edge_length", spec.edge_length);
  if (!spec.holes.empty())
    throw InputError("sheet: holes need an unstructured sheet (structured = false)");
  const int nx = std::max(1, static_cast<int>(std::ceil(spec.width / spec.edge_length - 1e-9)));
  const int ny = std::max(1, static_cast<int>(std::ceil(spec.height / spec.edge_length - 1e-9)));
  TriMesh mesh;
  mesh.vertices.resize((nx + 1) * (ny + 1), 3);
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      mesh.vertices.row(id(i, j)) << -0.5 * spec.width + spec.width * i / nx,
          -0.5 * spec.height + spec.height * j / ny, 0.0;
  mesh.triangles.resize(2 * nx * ny, 3);
  int f = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if ((i + j) % 2 == 0) {
        mesh.triangles.row(f++) << id(i, j), id(i + 1, j), id(i + 1, j + 1);
        mesh.triangles.row(f++) << id(i, j), id(i + 1, j + 1), id(i, j + 1);
      } else {
        mesh.triangles.row(f++) << id(i, j), id(i + 1, j), id(i, j + 1);
        mesh.triangles.row(f++) << id(i + 1, j), id(i + 1, j + 1), id(i, j + 1);
      }
    }
  return mesh;
}

}  // namespace psq
