#pragma once
// Connectivity derived from a triangle list: edges, interior hinges, boundary loops and
// vertex one-rings. Built once per mesh; every element loop in the engine reads it.

#include <array>
#include <string>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// An interior edge with its two adjacent triangles. Triangle `face0` contains the directed
/// edge v0→v1 followed by `opposite0`; `face1` contains v1→v0 followed by `opposite1`.
/// This fixes the sign of the dihedral angle.
struct Hinge {
  int v0, v1;
  int opposite0, opposite1;
  int face0, face1;
};

struct MeshTopology {
  std::vector<std::array<int, 2>> edges;        ///< unique undirected edges, v0 < v1
  std::vector<std::array<int, 2>> edge_faces;   ///< adjacent triangles; second is -1 on the boundary
  std::vector<std::array<int, 3>> face_edges;   ///< edge i of a face is opposite its vertex i
  std::vector<Hinge> hinges;                    ///< one per interior edge
  std::vector<std::vector<int>> boundary_loops; ///< closed vertex loops, following face orientation
  std::vector<std::vector<int>> vertex_neighbors; ///< sorted one-ring of each vertex

  /// Builds the topology. Throws InputError (naming `source`) if an edge is shared by more
  /// than two triangles or two triangles orient a shared edge the same way.
  static MeshTopology build(const TriMesh& mesh, const std::string& source = "mesh");
};

}  // namespace psq
