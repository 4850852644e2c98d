#pragma once
// The edge length of a scene's generated meshes, which the benchmarks scale to a size.

#include "engine/scene/scene.hpp"

namespace psq::bench {

/// The edge length of a generated mesh: its generator's field (a sheet's for a mesh file,
/// which has none and does not read it).
inline double generated_edge_length(const MeshSource& mesh) {
  if (mesh.kind == MeshSource::Kind::Cylinder) return mesh.cylinder.edge_length;
  if (mesh.kind == MeshSource::Kind::Sphere) return mesh.sphere.edge_length;
  if (mesh.kind == MeshSource::Kind::CylindricalPanel) return mesh.cylindrical_panel.edge_length;
  if (mesh.kind == MeshSource::Kind::SphericalPanel) return mesh.spherical_panel.edge_length;
  return mesh.sheet.edge_length;
}

/// Sets the edge length of every generator: the mesh's own one reads it, a mesh file ignores it.
inline void set_generated_edge_length(MeshSource& mesh, double edge) {
  mesh.sheet.edge_length = mesh.cylinder.edge_length = mesh.sphere.edge_length = edge;
  mesh.cylindrical_panel.edge_length = mesh.spherical_panel.edge_length = edge;
}

}  // namespace psq::bench
