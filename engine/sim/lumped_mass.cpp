#include "engine/sim/lumped_mass.hpp"

#include <Eigen/Geometry>

namespace psq {

Eigen::VectorXd lumped_vertex_masses(const TriMesh& rest, const Material& material) {
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(rest.vertex_count());
  const double areal_density = material.density * material.thickness;
  for (int f = 0; f < rest.triangle_count(); ++f) {
    const Eigen::Vector3d a = rest.vertices.row(rest.triangles(f, 0));
    const Eigen::Vector3d b = rest.vertices.row(rest.triangles(f, 1));
    const Eigen::Vector3d c = rest.vertices.row(rest.triangles(f, 2));
    const double share = areal_density * 0.5 * (b - a).cross(c - a).norm() / 3.0;
    for (int k = 0; k < 3; ++k) mass[rest.triangles(f, k)] += share;
  }
  return mass;
}

}  // namespace psq
