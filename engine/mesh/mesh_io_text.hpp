#pragma once
// Pieces shared by the mesh file parsers (private to engine/mesh): line splitting, number
// parsing with located errors, and accumulation of the parsed elements.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "engine/mesh/mesh_checks.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Walks a text line by line, tracking the 1-based line number and the byte offset.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text) {}

  /// Next line without its terminator ("\n" or "\r\n"); false at the end of the text.
  bool next(std::string_view& line);
  /// Like next(), but skips lines that hold only whitespace.
  bool next_nonblank(std::string_view& line);
  [[nodiscard]] long line_number() const { return line_number_; }
  /// Byte offset just past the terminator of the last line returned.
  [[nodiscard]] std::size_t offset() const { return offset_; }

 private:
  std::string_view text_;
  std::size_t offset_ = 0;
  long line_number_ = 0;
};

/// The whitespace-separated words of a line.
std::vector<std::string_view> split_words(std::string_view line);

/// The line up to its first '#'.
std::string_view strip_comment(std::string_view line);

/// Parses a whole word as a real number. "nan" and "inf" are accepted here so that the mesh
/// check can report them as non-finite coordinates. InputError at file:line otherwise.
double parse_real(std::string_view word, const std::string& file, long line, std::string_view what);

/// Parses a whole word as an integer; InputError at file:line if it is not one.
long long parse_integer(std::string_view word, const std::string& file, long line,
                        std::string_view what);

/// Parses a whole word as an element count in [0, 2³¹); InputError at file:line otherwise.
int parse_count(std::string_view word, const std::string& file, long line, std::string_view what);

/// Parses a whole word as a 0-based vertex index that fits an int; InputError at file:line
/// otherwise (whether it names an existing vertex is check_mesh's job).
int parse_index(std::string_view word, const std::string& file, long line);

/// A parsed mesh together with where its elements came from.
struct ParsedMesh {
  TriMesh mesh;
  MeshOrigin origin;
};

/// Collects vertices and triangles, with their source lines, while a file is parsed.
class MeshBuilder {
 public:
  void add_vertex(double x, double y, double z, long line);
  void add_triangle(int a, int b, int c, long line);
  [[nodiscard]] int vertex_count() const { return static_cast<int>(vertex_lines_.size()); }
  /// The mesh in TriMesh form; `index_base` is how the file numbers vertices.
  ParsedMesh finish(const std::string& source, int index_base);

 private:
  std::vector<double> coordinates_;
  std::vector<int> corners_;
  std::vector<long> vertex_lines_;
  std::vector<long> triangle_lines_;
};

}  // namespace psq
