// Structured panels of cylinders and spheres: (u, v) grids mapped onto the surface.

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_checks.hpp"
#include "engine/mesh/structured_grid.hpp"

namespace psq {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

/// Throws InputError unless `degrees` lies in (low, high] (or (low, high) when !high_allowed).
void require_angle(const std::string& generator, const std::string& parameter, double degrees,
                   double low, double high, bool high_allowed) {
  const bool ok = std::isfinite(degrees) && degrees > low &&
                  (high_allowed ? degrees <= high : degrees < high);
  if (!ok)
    throw InputError(fmt::format("{}: {} must be in ({:g}, {:g}{} (got {})", generator, parameter,
                                 low, high, high_allowed ? "]" : ")", degrees));
}

/// Columns of an arc of `degrees` whose widest circle has radius `radius`: closed rings in
/// multiples of 4, open arcs in even numbers.
GridIndexing arc_grid(double radius, double degrees, double across, double edge_length) {
  const bool closed = degrees == 360.0;
  return {round_up_cells(radius * degrees * kDegree / edge_length, closed ? 4 : 2),
          round_up_cells(across / edge_length, 2), closed};
}

/// The azimuth of column i of `grid`, spanning `degrees` centred on +x [rad].
double column_angle(const GridIndexing& grid, double degrees, int i) {
  return (-0.5 + static_cast<double>(i) / grid.nu) * degrees * kDegree;
}

}  // namespace

TriMesh make_cylindrical_panel(const CylindricalPanelGenerator& spec) {
  const std::string name = "cylindrical_panel";
  require_positive(name, "radius", spec.radius);
  require_positive(name, "height", spec.height);
  require_positive(name, "edge_length", spec.edge_length);
  require_angle(name, "angle_degrees", spec.angle_degrees, 0, 360, true);
  require_edge_below(name, spec.edge_length, "height", spec.height);
  require_edge_below(name, spec.edge_length, "arc length", spec.radius * spec.angle_degrees * kDegree);
  const GridIndexing grid = arc_grid(spec.radius, spec.angle_degrees, spec.height, spec.edge_length);
  TriMesh mesh;
  mesh.vertices.resize(grid.vertex_count(), 3);
  for (int j = 0; j <= grid.nv; ++j)
    for (int i = 0; i < grid.columns(); ++i) {
      const double angle = column_angle(grid, spec.angle_degrees, i);
      mesh.vertices.row(grid.id(i, j)) << spec.radius * std::cos(angle),
          spec.radius * std::sin(angle), spec.height * j / grid.nv;
    }
  mesh.triangles = checkerboard_triangles(grid);  // ∂u (along the arc) × ∂v (+z): outward
  return mesh;
}

TriMesh make_spherical_panel(const SphericalPanelGenerator& spec) {
  const std::string name = "spherical_panel";
  require_positive(name, "radius", spec.radius);
  require_positive(name, "edge_length", spec.edge_length);
  require_angle(name, "polar_min_degrees", spec.polar_min_degrees, 0, 180, false);
  require_angle(name, "polar_max_degrees", spec.polar_max_degrees, spec.polar_min_degrees, 180,
                false);
  require_angle(name, "azimuth_degrees", spec.azimuth_degrees, 0, 360, true);
  const double low = spec.polar_min_degrees * kDegree, high = spec.polar_max_degrees * kDegree;
  const double widest =
      low <= 0.5 * std::numbers::pi && high >= 0.5 * std::numbers::pi
          ? 1.0
          : std::max(std::sin(low), std::sin(high));
  require_edge_below(name, spec.edge_length, "meridian length", spec.radius * (high - low));
  const GridIndexing grid =
      arc_grid(spec.radius * widest, spec.azimuth_degrees, spec.radius * (high - low),
               spec.edge_length);
  TriMesh mesh;
  mesh.vertices.resize(grid.vertex_count(), 3);
  // Row 0 is at polar_max and rows run toward the pole, so that ∂u (east) × ∂v (north) points
  // outward.
  for (int j = 0; j <= grid.nv; ++j) {
    const double polar = high - (high - low) * j / grid.nv;
    for (int i = 0; i < grid.columns(); ++i) {
      const double azimuth = column_angle(grid, spec.azimuth_degrees, i);
      mesh.vertices.row(grid.id(i, j)) << spec.radius * std::sin(polar) * std::cos(azimuth),
          spec.radius * std::sin(polar) * std::sin(azimuth), spec.radius * std::cos(polar);
    }
  }
  mesh.triangles = checkerboard_triangles(grid);
  return mesh;
}

}  // namespace psq
