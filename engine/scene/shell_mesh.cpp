#include "engine/scene/shell_mesh.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <numbers>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_io.hpp"

namespace psq {
namespace {

TriMesh generate(const MeshSource& source) {
  switch (source.kind) {
    case MeshSource::Kind::File:
      return read_mesh(source.file);
    case MeshSource::Kind::Sheet:
      return make_sheet(source.sheet);
    case MeshSource::Kind::Cylinder:
      return make_cylinder(source.cylinder);
    case MeshSource::Kind::Sphere:
      return make_sphere(source.sphere);
    case MeshSource::Kind::CylindricalPanel:
      return make_cylindrical_panel(source.cylindrical_panel);
    case MeshSource::Kind::SphericalPanel:
      return make_spherical_panel(source.spherical_panel);
  }
  throw InputError("mesh source of unknown kind");
}

}  // namespace

void apply_placement(const MeshSource& source, Positions& vertices) {
  if (!(source.scale > 0))
    throw InputError(fmt::format("mesh placement: scale must be positive (got {})", source.scale));
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  if (source.rotation_degrees != 0) {
    if (source.rotation_axis.norm() == 0)
      throw InputError("mesh placement: rotation_axis must not be zero when rotating");
    const double angle = source.rotation_degrees * std::numbers::pi / 180.0;
    rotation = Eigen::AngleAxisd(angle, source.rotation_axis.normalized()).toRotationMatrix();
  }
  // Rows are points: (R·s·x)ᵀ = s·xᵀ·Rᵀ.
  vertices =
      (source.scale * vertices * rotation.transpose()).rowwise() + source.translation.transpose();
}

TriMesh build_shell_mesh(const MeshSource& source) {
  TriMesh mesh = generate(source);
  apply_placement(source, mesh.vertices);
  return mesh;
}

}  // namespace psq
