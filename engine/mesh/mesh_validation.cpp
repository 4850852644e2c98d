#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io.hpp"
#include "engine/mesh/mesh_checks.hpp"
#include "engine/mesh/topology.hpp"

namespace psq {
namespace {

/// Triangles with area below this fraction of the squared bounding-box diagonal are treated
/// as degenerate: their normals and element matrices would be dominated by round-off.
constexpr double kRelativeAreaFloor = 1e-14;

long line_of(const std::vector<long>& lines, int element) {
  return lines.empty() ? 0 : lines[static_cast<std::size_t>(element)];
}

void check_not_empty(const TriMesh& mesh, const MeshOrigin& origin) {
  if (mesh.vertex_count() > 0 && mesh.triangle_count() > 0) return;
  throw InputError(located_message(
      origin.source, 0,
      fmt::format("empty mesh ({} vertices, {} triangles); a mesh needs at least one triangle",
                  mesh.vertex_count(), mesh.triangle_count())));
}

void check_finite_coordinates(const TriMesh& mesh, const MeshOrigin& origin) {
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.vertices.row(v).allFinite()) continue;
    throw InputError(located_message(
        origin.source, line_of(origin.vertex_lines, v),
        fmt::format("vertex {} has a non-finite coordinate ({}, {}, {})", v + origin.index_base,
                    mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2))));
  }
}

void check_triangle_indices(const TriMesh& mesh, const MeshOrigin& origin) {
  const int n = mesh.vertex_count();
  for (int f = 0; f < mesh.triangle_count(); ++f) {
    const long line = line_of(origin.triangle_lines, f);
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles(f, k);
      if (v < 0 || v >= n)
        throw InputError(located_message(
            origin.source, line,
            fmt::format("triangle {} refers to vertex {}, but vertices are numbered {}..{}", f,
                        v + origin.index_base, origin.index_base, n - 1 + origin.index_base)));
      if (v == mesh.triangles(f, (k + 1) % 3))
        throw InputError(located_message(
            origin.source, line,
            fmt::format("triangle {} repeats vertex {}", f, v + origin.index_base)));
    }
  }
}

void check_triangle_areas(const TriMesh& mesh, const MeshOrigin& origin) {
  // Coordinates are scaled by the diagonal first so that huge or tiny meshes neither
  // overflow nor underflow the squared quantities.
  const double diagonal = bounding_box_diagonal(mesh.vertices);
  for (int f = 0; f < mesh.triangle_count(); ++f) {
    const Eigen::RowVector3d a = mesh.vertices.row(mesh.triangles(f, 0));
    const Eigen::RowVector3d ab = (mesh.vertices.row(mesh.triangles(f, 1)) - a) / diagonal;
    const Eigen::RowVector3d ac = (mesh.vertices.row(mesh.triangles(f, 2)) - a) / diagonal;
    const double relative_area = 0.5 * ab.cross(ac).norm();
    if (relative_area > kRelativeAreaFloor) continue;
    throw InputError(located_message(
        origin.source, line_of(origin.triangle_lines, f),
        fmt::format("triangle {} is degenerate (area {:.3g} × diagonal², below {:g}); remove it "
                    "or move its vertices apart",
                    f, relative_area, kRelativeAreaFloor)));
  }
}

}  // namespace

void check_mesh(const TriMesh& mesh, const MeshOrigin& origin) {
  check_not_empty(mesh, origin);
  check_finite_coordinates(mesh, origin);
  check_triangle_indices(mesh, origin);
  check_triangle_areas(mesh, origin);
  MeshTopology::build(mesh, origin.source);
}

void validate_mesh(const TriMesh& mesh, const std::string& source) {
  check_mesh(mesh, MeshOrigin{source, {}, {}, 0});
}

void require_positive(const std::string& generator, const std::string& parameter, double value) {
  if (value > 0 && std::isfinite(value)) return;
  throw InputError(
      fmt::format("{}: {} must be a positive finite number (got {})", generator, parameter, value));
}

void require_edge_below(const std::string& generator, double edge_length,
                        const std::string& limit_name, double limit) {
  if (edge_length < limit) return;
  throw InputError(fmt::format("{}: edge_length ({}) must be smaller than the {} ({})", generator,
                               edge_length, limit_name, limit));
}

}  // namespace psq
