#pragma once
// Turning a scene's vertex selectors (pins, loads) into vertex indices of a built mesh.

#include <string>
#include <vector>

#include "engine/mesh/topology.hpp"
#include "engine/mesh/tri_mesh.hpp"
#include "engine/scene/scene.hpp"

namespace psq {

/// Boundary loops of a mesh ordered by vertex count, largest first; loops of equal size keep
/// the order of MeshTopology::boundary_loops. This order defines `boundary_loop = k`.
std::vector<std::vector<int>> boundary_loops_by_size(const MeshTopology& topology);

/// The vertices a selector picks on `mesh`, sorted ascending, without repeats:
/// - Box: every vertex p with box_min ≤ p ≤ box_max componentwise; the box is widened by
///   1e-9 × the mesh's bounding-box diagonal so that a face of the box placed exactly on a
///   row of vertices catches them despite round-off.
/// - BoundaryLoop: the vertices of loop `boundary_loop` in boundary_loops_by_size order.
/// - List: the listed indices.
/// Throws InputError when nothing is selected, the loop does not exist or an index is out of
/// range. The message starts with the selector's source file and line (when known), names it
/// with `what` (e.g. "pin 'left' of shell 'sheet'") and shows the selector and the mesh extent.
std::vector<int> select_vertices(const VertexSelector& selector, const TriMesh& mesh,
                                 const MeshTopology& topology, const std::string& what);

}  // namespace psq
