#pragma once
// The per-format readers and writers behind read_mesh / write_mesh (private to engine/mesh).
// Readers only parse: they report syntax errors with file and line, and leave the geometric
// and topological checks to check_mesh.

#include <ostream>
#include <string>
#include <string_view>

#include "engine/mesh/mesh_io_text.hpp"

namespace psq {

/// Wavefront OBJ: `v x y z` and triangular `f` lines (index forms a, a/b, a/b/c, a//c;
/// negative indices count back from the last vertex read). Other statements are ignored.
ParsedMesh parse_obj(std::string_view text, const std::string& file);

/// OFF: "OFF", then "vertices faces edges", vertex lines and "3 a b c" face lines.
ParsedMesh parse_off(std::string_view text, const std::string& file);

/// PLY in ASCII, binary_little_endian or binary_big_endian; vertex x, y, z and the face list
/// `vertex_indices` (or `vertex_index`); other elements and properties are skipped.
ParsedMesh parse_ply(std::string_view bytes, const std::string& file);

void write_obj(std::ostream& out, const TriMesh& mesh);
void write_off(std::ostream& out, const TriMesh& mesh);
/// Binary little-endian PLY with double coordinates, so that a round trip is exact.
void write_ply(std::ostream& out, const TriMesh& mesh);

}  // namespace psq
