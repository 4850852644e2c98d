#include <cmath>
#include <numbers>

#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_checks.hpp"

namespace psq {
namespace {

void check_cylinder(const CylinderGenerator& spec) {
  require_positive("cylinder", "radius", spec.radius);
  require_positive("cylinder", "height", spec.height);
  require_positive("cylinder", "edge_length", spec.edge_length);
  require_edge_below("cylinder", spec.edge_length, "height", spec.height);
  require_edge_below("cylinder", spec.edge_length, "diameter", 2 * spec.radius);
}

}  // namespace

TriMesh make_cylinder(const CylinderGenerator& spec) {
  check_cylinder(spec);
  // Odd rings are rotated by half a step and rings sit one equilateral-triangle height
  // (√3/2 · edge) apart, so the strip between two rings is made of near-equilateral triangles.
  const int around =
      static_cast<int>(std::lround(2 * std::numbers::pi * spec.radius / spec.edge_length));
  const double ring_spacing = 0.5 * std::numbers::sqrt3 * spec.edge_length;
  const int rings = static_cast<int>(std::lround(spec.height / ring_spacing)) + 1;
  const auto id = [around](int ring, int k) {
    return ring * around + (k % around + around) % around;
  };

  TriMesh mesh;
  mesh.vertices.resize(rings * around, 3);
  for (int ring = 0; ring < rings; ++ring)
    for (int k = 0; k < around; ++k) {
      const double angle = 2 * std::numbers::pi * (k + 0.5 * (ring % 2)) / around;
      mesh.vertices.row(id(ring, k)) << spec.radius * std::cos(angle),
          spec.radius * std::sin(angle), spec.height * ring / (rings - 1);
    }
  // Between rings r and r+1, top vertex `k + shift` lies half a step past bottom vertex k.
  // Both triangles wind counter-clockwise seen from outside (normal along +radial).
  mesh.triangles.resize(2 * (rings - 1) * around, 3);
  int f = 0;
  for (int ring = 0; ring + 1 < rings; ++ring) {
    const int shift = ring % 2;
    for (int k = 0; k < around; ++k) {
      const int top = k + shift;
      mesh.triangles.row(f++) << id(ring, k), id(ring, k + 1), id(ring + 1, top);
      mesh.triangles.row(f++) << id(ring, k), id(ring + 1, top), id(ring + 1, top - 1);
    }
  }
  return mesh;
}

}  // namespace psq
