#include <fmt/format.h>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io_formats.hpp"

namespace psq {
namespace {

/// The words of the next line that holds anything besides comments and whitespace, or
/// InputError "unexpected end of file" saying what was being read.
std::vector<std::string_view> next_statement(LineCursor& cursor, const std::string& file,
                                             std::string_view expected) {
  std::string_view line;
  while (cursor.next(line)) {
    std::vector<std::string_view> words = split_words(strip_comment(line));
    if (!words.empty()) return words;
  }
  throw InputError(
      located_message(file, cursor.line_number(),
                      fmt::format("unexpected end of file while reading {}", expected)));
}

void parse_off_vertex(LineCursor& cursor, MeshBuilder& builder, const std::string& file,
                      int index) {
  const auto words = next_statement(cursor, file, fmt::format("vertex {}", index));
  const long line = cursor.line_number();
  if (words.size() < 3)
    throw InputError(located_message(
        file, line,
        fmt::format("vertex {} has {} coordinates; expected x y z", index, words.size())));
  builder.add_vertex(parse_real(words[0], file, line, "x coordinate"),
                     parse_real(words[1], file, line, "y coordinate"),
                     parse_real(words[2], file, line, "z coordinate"), line);
}

void parse_off_face(LineCursor& cursor, MeshBuilder& builder, const std::string& file, int index) {
  const auto words = next_statement(cursor, file, fmt::format("face {}", index));
  const long line = cursor.line_number();
  const long long corners = parse_integer(words[0], file, line, "face vertex count");
  if (corners != 3)
    throw InputError(located_message(
        file, line,
        fmt::format("face {} has {} vertices; only triangles are supported (triangulate the mesh)",
                    index, corners)));
  // Colour values may follow the three indices.
  if (words.size() < 4)
    throw InputError(located_message(
        file, line, fmt::format("face {} lists {} of its 3 indices", index, words.size() - 1)));
  builder.add_triangle(parse_index(words[1], file, line), parse_index(words[2], file, line),
                       parse_index(words[3], file, line), line);
}

}  // namespace

ParsedMesh parse_off(std::string_view text, const std::string& file) {
  LineCursor cursor(text);
  std::vector<std::string_view> words = next_statement(cursor, file, "the OFF header");
  if (words[0] != "OFF")
    throw InputError(located_message(file, cursor.line_number(),
                                     fmt::format("expected 'OFF' header, found '{}'", words[0])));
  // The counts usually have a line of their own but may follow "OFF" directly.
  words.erase(words.begin());
  if (words.empty()) words = next_statement(cursor, file, "the vertex and face counts");
  const long counts_line = cursor.line_number();
  if (words.size() < 2)
    throw InputError(located_message(
        file, counts_line, "expected the vertex and face counts ('vertices faces edges')"));
  const int vertex_count = parse_count(words[0], file, counts_line, "vertex count");
  const int face_count = parse_count(words[1], file, counts_line, "face count");
  MeshBuilder builder;
  for (int v = 0; v < vertex_count; ++v) parse_off_vertex(cursor, builder, file, v);
  for (int f = 0; f < face_count; ++f) parse_off_face(cursor, builder, file, f);
  return builder.finish(file, 0);
}

void write_off(std::ostream& out, const TriMesh& mesh) {
  out << fmt::format("OFF\n{} {} 0\n", mesh.vertex_count(), mesh.triangle_count());
  for (int v = 0; v < mesh.vertex_count(); ++v)
    out << fmt::format("{} {} {}\n", mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
  for (int f = 0; f < mesh.triangle_count(); ++f)
    out << fmt::format("3 {} {} {}\n", mesh.triangles(f, 0), mesh.triangles(f, 1),
                       mesh.triangles(f, 2));
}

}  // namespace psq
