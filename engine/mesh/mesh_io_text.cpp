#include "engine/mesh/mesh_io_text.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <climits>

#include "engine/core/error.hpp"

namespace psq {
namespace {

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

/// Throws unless from_chars consumed the whole word without error.
void require_parsed(std::from_chars_result result, std::string_view digits, std::string_view word,
                    const std::string& file, long line, std::string_view what,
                    std::string_view expected) {
  if (result.ec == std::errc::result_out_of_range)
    throw InputError(located_message(
        file, line,
        fmt::format("malformed {}: '{}' is out of range for {}", what, word, expected)));
  if (result.ec != std::errc() || result.ptr != digits.data() + digits.size())
    throw InputError(located_message(
        file, line, fmt::format("malformed {}: '{}' is not {}", what, word, expected)));
}

/// The word without a leading '+', which from_chars rejects but some exporters write.
std::string_view without_plus(std::string_view word) {
  if (word.size() > 1 && word.front() == '+' && word[1] != '-') word.remove_prefix(1);
  return word;
}

}  // namespace

bool LineCursor::next(std::string_view& line) {
  if (offset_ >= text_.size()) return false;
  const std::size_t end = text_.find('\n', offset_);
  const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
  line = text_.substr(offset_, stop - offset_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  offset_ = end == std::string_view::npos ? text_.size() : end + 1;
  ++line_number_;
  return true;
}

bool LineCursor::next_nonblank(std::string_view& line) {
  while (next(line))
    for (char c : line)
      if (!is_space(c)) return true;
  return false;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

std::string_view strip_comment(std::string_view line) { return line.substr(0, line.find('#')); }

double parse_real(std::string_view word, const std::string& file, long line,
                  std::string_view what) {
  const std::string_view digits = without_plus(word);
  double value = 0;
  require_parsed(std::from_chars(digits.data(), digits.data() + digits.size(), value), digits, word,
                 file, line, what, "a number");
  return value;
}

long long parse_integer(std::string_view word, const std::string& file, long line,
                        std::string_view what) {
  const std::string_view digits = without_plus(word);
  long long value = 0;
  require_parsed(std::from_chars(digits.data(), digits.data() + digits.size(), value), digits, word,
                 file, line, what, "an integer");
  return value;
}

int parse_count(std::string_view word, const std::string& file, long line, std::string_view what) {
  const long long value = parse_integer(word, file, line, what);
  if (value < 0 || value > INT_MAX)
    throw InputError(located_message(
        file, line, fmt::format("{} {} is out of range [0, {}]", what, value, INT_MAX)));
  return static_cast<int>(value);
}

int parse_index(std::string_view word, const std::string& file, long line) {
  const long long value = parse_integer(word, file, line, "face index");
  if (value < 0 || value >= INT_MAX)
    throw InputError(located_message(
        file, line,
        fmt::format("face index {} is out of range (vertices are numbered from 0)", value)));
  return static_cast<int>(value);
}

void MeshBuilder::add_vertex(double x, double y, double z, long line) {
  coordinates_.insert(coordinates_.end(), {x, y, z});
  vertex_lines_.push_back(line);
}

void MeshBuilder::add_triangle(int a, int b, int c, long line) {
  corners_.insert(corners_.end(), {a, b, c});
  triangle_lines_.push_back(line);
}

ParsedMesh MeshBuilder::finish(const std::string& source, int index_base) {
  ParsedMesh parsed;
  parsed.mesh.vertices = Eigen::Map<const Positions>(
      coordinates_.data(), static_cast<Eigen::Index>(vertex_lines_.size()), 3);
  parsed.mesh.triangles = Eigen::Map<const Triangles>(
      corners_.data(), static_cast<Eigen::Index>(triangle_lines_.size()), 3);
  parsed.origin =
      MeshOrigin{source, std::move(vertex_lines_), std::move(triangle_lines_), index_base};
  return parsed;
}

}  // namespace psq
