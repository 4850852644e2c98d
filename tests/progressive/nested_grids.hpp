#pragma once
// Hand-built two-level hierarchies from nested structured grids, independent of the decimation
// code: a coarse grid and its 2× refinement over one parameter domain, mapped to 3D by the same
// shape function. Every fine vertex lies in a coarse parameter triangle with exact barycentric
// coordinates; pinned sets are taken from the finest system.

#include <filesystem>
#include <functional>
#include <vector>

#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/scene/scene.hpp"

namespace psq::test {

/// Maps parameters (u, v) ∈ [0, 1]² to a rest position.
using Shape = std::function<Eigen::Vector3d(double u, double v)>;

/// A grid of nu × nv cells with alternating diagonals; closed in u (a tube) when `closed_u`.
struct GridSpec {
  int nu = 2, nv = 2;
  bool closed_u = false;
  Shape shape;
};

TriMesh grid_mesh(const GridSpec& spec);

/// The rest meshes of `coarse` and its 2× refinement, with the refinement's vertices located
/// on the coarse grid; `fine_pin_group` per fine vertex (coarse vertices inherit the group of
/// the fine vertex they coincide with).
MeshHierarchy nested_hierarchy(const GridSpec& coarse, const std::vector<int>& fine_pin_group);

/// The refinement of `coarse` (nu and nv doubled).
GridSpec refined(const GridSpec& coarse);

/// Writes the mesh to `dir`/name.obj and points the scene's only shell at it.
void use_mesh_file(Scene& scene, const TriMesh& mesh, const std::filesystem::path& dir,
                   const std::string& name);

/// Shapes of the scene library's meshes: the drape and twist sheets (width × height in the
/// z = 0 plane, centred at the origin) and the open cylinder (axis z, from z = 0 to height).
Shape sheet_shape(double width, double height);
Shape cylinder_shape(double radius, double height);

}  // namespace psq::test
