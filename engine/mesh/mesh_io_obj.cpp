#include <fmt/format.h>

#include <climits>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io_formats.hpp"

namespace psq {
namespace {

/// The 0-based vertex of one corner of an `f` statement ("7", "7/2", "7/2/5", "7//5", "-1").
/// Positive indices may refer to vertices defined later; check_mesh bounds them.
int resolve_corner(std::string_view word, int vertices_so_far, const std::string& file, long line) {
  const long long index = parse_integer(word.substr(0, word.find('/')), file, line, "face index");
  if (index == 0)
    throw InputError(
        located_message(file, line, "face index 0 is invalid: OBJ numbers vertices from 1"));
  const long long resolved = index > 0 ? index - 1 : vertices_so_far + index;
  if (resolved < 0 || resolved >= INT_MAX)
    throw InputError(
        located_message(file, line,
                        fmt::format("face index {} is out of range ({} vertices read so far)",
                                    index, vertices_so_far)));
  return static_cast<int>(resolved);
}

void parse_vertex(const std::vector<std::string_view>& words, MeshBuilder& builder,
                  const std::string& file, long line) {
  // An optional w or per-vertex colour may follow x y z; neither matters here.
  if (words.size() < 4)
    throw InputError(located_message(
        file, line, fmt::format("vertex has {} coordinates; 'v' needs x y z", words.size() - 1)));
  builder.add_vertex(parse_real(words[1], file, line, "x coordinate"),
                     parse_real(words[2], file, line, "y coordinate"),
                     parse_real(words[3], file, line, "z coordinate"), line);
}

void parse_face(const std::vector<std::string_view>& words, MeshBuilder& builder,
                const std::string& file, long line) {
  const std::size_t corners = words.size() - 1;
  if (corners != 3)
    throw InputError(located_message(
        file, line,
        fmt::format("face has {} vertices; only triangles are supported (triangulate the mesh)",
                    corners)));
  const int n = builder.vertex_count();
  builder.add_triangle(resolve_corner(words[1], n, file, line),
                       resolve_corner(words[2], n, file, line),
                       resolve_corner(words[3], n, file, line), line);
}

}  // namespace

ParsedMesh parse_obj(std::string_view text, const std::string& file) {
  MeshBuilder builder;
  LineCursor cursor(text);
  std::string_view line;
  while (cursor.next(line)) {
    const std::vector<std::string_view> words = split_words(strip_comment(line));
    if (words.empty()) continue;
    if (words[0] == "v")
      parse_vertex(words, builder, file, cursor.line_number());
    else if (words[0] == "f")
      parse_face(words, builder, file, cursor.line_number());
  }
  return builder.finish(file, 1);
}

void write_obj(std::ostream& out, const TriMesh& mesh) {
  // fmt's shortest round-trip formatting makes write-then-read exact.
  for (int v = 0; v < mesh.vertex_count(); ++v)
    out << fmt::format("v {} {} {}\n", mesh.vertices(v, 0), mesh.vertices(v, 1),
                       mesh.vertices(v, 2));
  for (int f = 0; f < mesh.triangle_count(); ++f)
    out << fmt::format("f {} {} {}\n", mesh.triangles(f, 0) + 1, mesh.triangles(f, 1) + 1,
                       mesh.triangles(f, 2) + 1);
}

}  // namespace psq
