#pragma once
// Checks shared by the mesh readers, validate_mesh and the generators (private to engine/mesh).

#include <string>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Where a mesh came from, so that errors can point at the offending line. The line vectors
/// are either empty (no file, or a binary file: errors then name the element index only) or
/// hold the 1-based line of each vertex and triangle.
struct MeshOrigin {
  std::string source;  ///< file name or description of the mesh
  std::vector<long> vertex_lines;
  std::vector<long> triangle_lines;
  int index_base = 0;  ///< how the file numbers vertices (OBJ: 1), for messages
};

/// Throws InputError unless the mesh is non-empty, has finite coordinates, in-range and
/// distinct indices per triangle, no triangle of area ≤ 1e-14·diag² (diag = bounding-box
/// diagonal) and a manifold, consistently oriented connectivity (MeshTopology::build).
void check_mesh(const TriMesh& mesh, const MeshOrigin& origin);

/// Throws InputError "<generator>: <parameter> must be a positive finite number" otherwise.
void require_positive(const std::string& generator, const std::string& parameter, double value);

/// Throws InputError unless edge_length < limit, naming edge_length and the limit it exceeds.
void require_edge_below(const std::string& generator, double edge_length,
                        const std::string& limit_name, double limit);

}  // namespace psq
