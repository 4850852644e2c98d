#pragma once
// Building a shell's rest mesh from its scene description.

#include "engine/mesh/tri_mesh.hpp"
#include "engine/scene/scene.hpp"

namespace psq {

/// Places a mesh rigidly (up to uniform scale): x ↦ R(axis, angle)·(scale·x) + translation,
/// with R the rotation by `rotation_degrees` about `rotation_axis` (normalized) through the
/// origin. Throws InputError if the scale is not positive or the axis is zero while the angle
/// is not.
void apply_placement(const MeshSource& source, Positions& vertices);

/// The rest mesh of a shell: read from `source.file` (read_mesh) or made by the chosen
/// generator, then placed by apply_placement.
TriMesh build_shell_mesh(const MeshSource& source);

}  // namespace psq
