#pragma once
// Reading and writing triangle meshes: OBJ, PLY (ASCII and binary little/big endian) and OFF,
// chosen by file extension.

#include <filesystem>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Reads and validates a mesh (see validate_mesh). Throws InputError naming the file and,
/// where it applies, the line: unreadable file, unknown extension, syntax errors, NaN/inf
/// coordinates, out-of-range or repeated indices in a face, polygons that are not
/// triangles, zero-area triangles, non-manifold edges, empty meshes.
TriMesh read_mesh(const std::filesystem::path& path);

/// Writes a mesh atomically (temporary file in the same directory, then rename).
/// PLY is written as binary little-endian. Throws InputError if the directory is not writable.
void write_mesh(const std::filesystem::path& path, const TriMesh& mesh);

/// Checks the geometry and connectivity of a mesh that did not come from a file
/// (generators, programmatic meshes) with the same rules as read_mesh; `source` names it.
void validate_mesh(const TriMesh& mesh, const std::string& source);

}  // namespace psq
