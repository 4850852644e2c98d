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

}  // namespace psq
