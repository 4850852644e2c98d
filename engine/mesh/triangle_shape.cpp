#include "engine/mesh/triangle_shape.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "engine/core/error.hpp"

namespace psq {

double triangle_shape_quality(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              const Eigen::Vector3d& c) {
  const double longest_squared =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return (b - a).cross(c - a).norm() / longest_squared;
}

void check_shell_triangle_shapes(const TriMesh& mesh, const std::string& source) {
  int slivers = 0;
  int worst = -1;
  double worst_quality = kSliverQualityFloor;
  for (int f = 0; f < mesh.triangle_count(); ++f) {
    const double quality = triangle_shape_quality(mesh.vertices.row(mesh.triangles(f, 0)),
                                                  mesh.vertices.row(mesh.triangles(f, 1)),
                                                  mesh.vertices.row(mesh.triangles(f, 2)));
    if (quality >= kSliverQualityFloor) continue;
    ++slivers;
    if (quality < worst_quality) {
      worst_quality = quality;
      worst = f;
    }
  }
  if (slivers == 0) return;
  throw InputError(fmt::format(
      "{}: triangle {} is a sliver: its height is {:.3g} × its longest edge, below {:g} ({} "
      "triangle(s) of the shell are); the solver cannot resolve the stiffness of such a "
      "triangle beside its neighbours' and would stop without moving. Remesh the shell "
      "without slivers (collapse a needle's short edge, flip a flat cap's long edge)",
      source, worst, worst_quality, kSliverQualityFloor, slivers));
}

}  // namespace psq
