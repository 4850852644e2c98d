#pragma once
// The shape of a shell's triangles: slivers whose elastic stiffness double precision cannot
// resolve beside their neighbours' (docs/stress.md, "Badly shaped input triangles").

#include <Eigen/Core>
#include <string>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// The smallest shape quality a shell's triangle may have. A needle's hinge stiffness grows as
/// the inverse cube of its quality relative to its neighbours' (hinge weight |e|²/A and the
/// squared angle gradient 1/h²), so at 1e-5 it spans 15 of double precision's 16 digits.
/// Measured on jobs/data/stress: needles of quality 1e-5 cost a third more Newton iterations,
/// at 1e-6 the first step is 1e-11 m and the frame is declared converged without moving; caps
/// (whose hinges keep a normal neighbour) hold out to 1e-7.
inline constexpr double kSliverQualityFloor = 1e-5;

/// A triangle's height over its longest edge, 2A/ℓ²_max: √3/2 for an equilateral triangle,
/// small for needles (one short edge) and caps (one angle near 180°) alike.
double triangle_shape_quality(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              const Eigen::Vector3d& c);

/// Throws InputError "<source>: triangle f is a sliver ..." naming the worst triangle below
/// kSliverQualityFloor, how many there are and what to change.
void check_shell_triangle_shapes(const TriMesh& mesh, const std::string& source);

}  // namespace psq
