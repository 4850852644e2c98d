#pragma once
// A level's state cut into its shells and colliders, each in its own vertex numbering, with its
// displacement from rest: one HDF5 file per finished level, which the XDMF sidecar shows as one
// block per part (a checkpoint holds every part in one concatenated mesh, and XDMF readers
// cannot renumber a part's triangles). Layout: docs/checkpoint-format.md, "Part meshes".

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

enum class PartKind { shell, collider };

/// Where one shell or collider lies in a system's concatenated vertex and triangle arrays.
struct PartRange {
  std::string name;
  PartKind kind = PartKind::shell;
  int first_vertex = 0;
  int vertex_count = 0;
  int first_triangle = 0;
  int triangle_count = 0;
};

/// One shell or collider at one moment, in its own vertex numbering.
struct PartMesh {
  std::string name;
  PartKind kind = PartKind::shell;
  Positions positions;       ///< n×3 (m)
  Positions rest_positions;  ///< n×3
  Triangles triangles;       ///< m×3, indices into this part's vertices
};

/// Every part of one level at one frame.
struct PartMeshes {
  int level = 0;
  int frame = 0;
  double time = 0.0;  ///< simulated time of `frame`, seconds
  std::vector<PartMesh> parts;
};

/// Cuts the system state `positions` (rest mesh `rest`) into the parts `ranges`. Throws
/// std::invalid_argument when a range lies outside the arrays or one of its triangles uses a
/// vertex outside it.
std::vector<PartMesh> split_into_parts(const Positions& positions, const TriMesh& rest,
                                       const std::vector<PartRange>& ranges);

/// Object names inside a part-meshes file, shared by its writer, its reader and the XDMF sidecar.
namespace part_mesh_layout {
/// The group of part `part` (0-based, in the order written): "/parts/<part>".
std::string group(std::size_t part);
inline constexpr std::string_view positions = "positions";
inline constexpr std::string_view rest_positions = "rest_positions";
inline constexpr std::string_view displacement = "displacement";
inline constexpr std::string_view triangles = "triangles";
}  // namespace part_mesh_layout

/// Writes `meshes` to `path` atomically (absent, the previous file, or the complete new one),
/// with each part's displacement (positions − rest positions). Throws InputError naming `path`
/// for inconsistent parts (shapes, triangle indices) or when the file cannot be written.
void write_part_meshes(const std::filesystem::path& path, const PartMeshes& meshes);

/// Reads a file write_part_meshes wrote. Throws InputError naming the file when it is missing,
/// damaged or not a part-meshes file.
PartMeshes read_part_meshes(const std::filesystem::path& path);

}  // namespace psq
