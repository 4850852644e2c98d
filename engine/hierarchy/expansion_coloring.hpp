#pragma once
// Greedy colouring of the vertex expansions between two levels, so that expansions of one
// colour can be refined in parallel (DESIGN.md §5).

#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Colours per coarse vertex such that no triangle of the finer level has vertices whose
/// parents are two different coarse vertices of one colour. `parent[v]`: the coarse vertex
/// each finer vertex v collapsed into. Greedy in vertex order: each vertex takes the
/// smallest colour none of its conflicting vertices has.
std::vector<int> color_expansions(const Triangles& finer_triangles, const std::vector<int>& parent,
                                  int coarse_vertex_count);

}  // namespace psq
