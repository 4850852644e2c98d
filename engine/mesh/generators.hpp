#pragma once
// Mesh generators for scenes and tests. Each produces a consistently oriented manifold mesh.

#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

struct SheetGenerator {
  double width = 1.0, height = 1.0;  ///< along x and y, centred at the origin, in the z=0 plane
  double edge_length = 0.05;         ///< target edge length
  struct Hole { double center_x, center_y, radius; };
  std::vector<Hole> holes;           ///< circular holes (unstructured sheets only)
  bool structured = false;           ///< regular grid (alternating diagonals) instead of Delaunay
};
struct CylinderGenerator {
  double radius = 0.5, height = 1.0;  ///< axis along z, from z=0 to z=height, open at both ends
  double edge_length = 0.05;
};
struct SphereGenerator {
  double radius = 0.5;  ///< centred at the origin
  double edge_length = 0.05;
};

/// Part of a cylinder around the z axis from z = 0 to z = height: the arc of `angle_degrees`
/// centred on the +x axis, as a structured grid (angle × height), outward normals.
struct CylindricalPanelGenerator {
  double radius = 1.0, height = 1.0;
  double angle_degrees = 90.0;  ///< in (0, 360]; 360 closes the ring (no seam)
  double edge_length = 0.05;    ///< target length of the grid's sides along the arc and the axis
};
/// A zone of a sphere centred at the origin: polar angles (from +z) in [polar_min, polar_max],
/// azimuths in the arc of `azimuth_degrees` centred on the +x axis, as a structured
/// latitude–longitude grid, outward normals.
struct SphericalPanelGenerator {
  double radius = 1.0;
  double polar_min_degrees = 10.0, polar_max_degrees = 90.0;  ///< 0 < min < max < 180
  double azimuth_degrees = 360.0;  ///< in (0, 360]; 360 closes the zone around z
  double edge_length = 0.05;       ///< target cell size where the zone is widest
};

/// Regular grid sheet: ⌈width/edge⌉ × ⌈height/edge⌉ cells, each split along a diagonal whose
/// direction alternates like a checkerboard, normals along +z. One diagonal direction throughout
/// would couple bending to twist in hinge models (a cantilever strip ends up ~30% too soft);
/// alternating them cancels that coupling. Holes are not supported here (InputError).
TriMesh make_structured_sheet(const SheetGenerator& spec);

/// Unstructured sheet by CGAL 2D conforming Delaunay meshing with the target edge length,
/// circular holes allowed; normals along +z. Dispatches to make_structured_sheet when
/// spec.structured is set.
TriMesh make_sheet(const SheetGenerator& spec);

/// Open cylinder at the target edge length, outward normals.
TriMesh make_cylinder(const CylinderGenerator& spec);

/// Sphere at the target edge length, outward normals.
TriMesh make_sphere(const SphereGenerator& spec);

/// The panel as a checkerboard grid (make_structured_sheet's diagonals). Cells: the arc
/// length R·angle and the height over edge_length, each rounded up to an even number, so a
/// grid line runs along the panel's middle both ways; a closed ring rounds up to a multiple
/// of 4, so vertices sit at every quarter turn (loads and symmetry pins there).
TriMesh make_cylindrical_panel(const CylindricalPanelGenerator& spec);

/// The zone as a checkerboard latitude–longitude grid with the counting rules of
/// make_cylindrical_panel: rows R·(polar_max − polar_min)/edge_length, columns the widest
/// circle's arc R·sin(θ)·azimuth/edge_length. Cells shrink in azimuth toward the pole (by
/// sin θ_min / sin θ_widest).
TriMesh make_spherical_panel(const SphericalPanelGenerator& spec);

}  // namespace psq
