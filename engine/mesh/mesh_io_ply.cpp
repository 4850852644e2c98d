#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cstdint>
#include <cstring>
#include <optional>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io_formats.hpp"

namespace psq {
namespace {

enum class PlyEncoding { ascii, little_endian, big_endian };
enum class PlyScalar { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

struct PlyProperty {
  std::string name;
  PlyScalar type;                       ///< the value type, or the item type of a list
  std::optional<PlyScalar> list_count;  ///< the count type, for list properties
};

struct PlyElement {
  std::string name;
  int count;
  std::vector<PlyProperty> properties;
  long line;  ///< header line declaring it
};

struct PlyHeader {
  PlyEncoding encoding;
  std::vector<PlyElement> elements;
  std::size_t data_offset;  ///< first byte after "end_header\n"
  long data_line;           ///< line number of the last header line
};

std::optional<PlyScalar> scalar_named(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, PlyScalar>, 16> names{{
      {"char", PlyScalar::int8},
      {"int8", PlyScalar::int8},
      {"uchar", PlyScalar::uint8},
      {"uint8", PlyScalar::uint8},
      {"short", PlyScalar::int16},
      {"int16", PlyScalar::int16},
      {"ushort", PlyScalar::uint16},
      {"uint16", PlyScalar::uint16},
      {"int", PlyScalar::int32},
      {"int32", PlyScalar::int32},
      {"uint", PlyScalar::uint32},
      {"uint32", PlyScalar::uint32},
      {"float", PlyScalar::float32},
      {"float32", PlyScalar::float32},
      {"double", PlyScalar::float64},
      {"float64", PlyScalar::float64},
  }};
  for (const auto& [n, type] : names)
    if (n == name) return type;
  return std::nullopt;
}

bool is_integral(PlyScalar type) {
  return type != PlyScalar::float32 && type != PlyScalar::float64;
}

std::size_t size_of(PlyScalar type) {
  switch (type) {
    case PlyScalar::int8:
    case PlyScalar::uint8: return 1;
    case PlyScalar::int16:
    case PlyScalar::uint16: return 2;
    case PlyScalar::int32:
    case PlyScalar::uint32:
    case PlyScalar::float32: return 4;
    case PlyScalar::float64: return 8;
  }
  return 8;
}

// ---- header ----------------------------------------------------------------------------------

class PlyHeaderParser {
 public:
  PlyHeaderParser(std::string_view bytes, const std::string& file) : cursor_(bytes), file_(file) {}

  PlyHeader parse() {
    std::string_view line;
    if (!cursor_.next(line) || split_words(line) != std::vector<std::string_view>{"ply"})
      fail("not a PLY file: the first line must be 'ply'");
    std::optional<PlyEncoding> encoding;
    while (cursor_.next(line)) {
      const std::vector<std::string_view> words = split_words(line);
      if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
      if (words[0] == "format")
        encoding = parse_format(words);
      else if (words[0] == "element")
        elements_.push_back(parse_element(words));
      else if (words[0] == "property")
        add_property(words);
      else if (words[0] == "end_header" && words.size() == 1)
        return finish(encoding);
      else
        fail(fmt::format("unknown PLY header line '{}'", line));
    }
    fail("missing 'end_header'");
  }

 private:
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(located_message(file_, cursor_.line_number(), message));
  }

  PlyEncoding parse_format(const std::vector<std::string_view>& words) const {
    if (words.size() == 3) {
      if (words[1] == "ascii") return PlyEncoding::ascii;
      if (words[1] == "binary_little_endian") return PlyEncoding::little_endian;
      if (words[1] == "binary_big_endian") return PlyEncoding::big_endian;
    }
    fail("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
  }

  PlyElement parse_element(const std::vector<std::string_view>& words) const {
    if (words.size() != 3) fail("expected 'element <name> <count>'");
    const long line = cursor_.line_number();
    return PlyElement{
        std::string(words[1]), parse_count(words[2], file_, line, "element count"), {}, line};
  }

  PlyScalar scalar(std::string_view name) const {
    const std::optional<PlyScalar> type = scalar_named(name);
    if (!type) fail(fmt::format("unknown PLY property type '{}'", name));
    return *type;
  }

  void add_property(const std::vector<std::string_view>& words) {
    if (elements_.empty()) fail("'property' before any 'element'");
    PlyProperty property;
    if (words.size() == 5 && words[1] == "list") {
      property = {std::string(words[4]), scalar(words[3]), scalar(words[2])};
      if (!is_integral(*property.list_count)) fail("a list count type must be an integer type");
    } else if (words.size() == 3) {
      property = {std::string(words[2]), scalar(words[1]), std::nullopt};
    } else {
      fail("expected 'property <type> <name>' or 'property list <count type> <type> <name>'");
    }
    elements_.back().properties.push_back(std::move(property));
  }

  PlyHeader finish(std::optional<PlyEncoding> encoding) const {
    if (!encoding) fail("the header has no 'format' line");
    return PlyHeader{*encoding, elements_, cursor_.offset(), cursor_.line_number()};
  }

  LineCursor cursor_;
  const std::string& file_;
  std::vector<PlyElement> elements_;
};

/// Where the vertex and face data sit among an element's properties.
struct PlyLayout {
  std::array<int, 3> xyz{-1, -1, -1};  ///< property index of x, y, z in "vertex"
  int face_indices = -1;               ///< property index of the index list in "face"
};

PlyLayout find_layout(const PlyHeader& header, const std::string& file) {
  PlyLayout layout;
  bool has_vertex = false;
  bool has_face = false;
  for (const PlyElement& element : header.elements) {
    // The layout holds one property index per role, valid for one declaration only.
    bool& seen = element.name == "vertex" ? has_vertex : has_face;
    if ((element.name == "vertex" || element.name == "face") && seen)
      throw InputError(located_message(
          file, element.line, fmt::format("element '{}' is declared twice", element.name)));
    const auto property_index = [&](auto matches) {
      const auto it = std::find_if(element.properties.begin(), element.properties.end(), matches);
      return it == element.properties.end() ? -1
                                            : static_cast<int>(it - element.properties.begin());
    };
    if (element.name == "vertex") {
      has_vertex = true;
      for (int axis = 0; axis < 3; ++axis) {
        const std::string name(1, "xyz"[axis]);
        layout.xyz[axis] = property_index([&](const PlyProperty& p) { return p.name == name; });
        if (layout.xyz[axis] < 0 || element.properties[layout.xyz[axis]].list_count)
          throw InputError(
              located_message(file, element.line,
                              fmt::format("element 'vertex' needs a scalar property '{}'", name)));
      }
    } else if (element.name == "face") {
      has_face = true;
      layout.face_indices = property_index([](const PlyProperty& p) {
        return p.name == "vertex_indices" || p.name == "vertex_index";
      });
      const PlyProperty* list =
          layout.face_indices < 0 ? nullptr : &element.properties[layout.face_indices];
      if (!list || !list->list_count || !is_integral(list->type))
        throw InputError(located_message(
            file, element.line,
            "element 'face' needs an integer list property 'vertex_indices' (or 'vertex_index')"));
    }
  }
  if (!has_vertex)
    throw InputError(located_message(file, header.data_line, "the header has no element 'vertex'"));
  return layout;
}

// ---- data ------------------------------------------------------------------------------------

/// The values of the data section, one element instance at a time, as text words.
class PlyAsciiValues {
 public:
  PlyAsciiValues(std::string_view data, long first_line, const std::string& file)
      : cursor_(data), first_line_(first_line), file_(file) {}

  void begin(const PlyElement& element, int index) {
    std::string_view line;
    if (!cursor_.next_nonblank(line))
      fail(fmt::format("unexpected end of file: {} {} of {} is missing", element.name, index,
                       element.count));
    words_ = split_words(line);
    next_word_ = 0;
  }

  double read(PlyScalar type) {
    if (next_word_ >= words_.size()) fail("too few values on this line");
    const std::string_view word = words_[next_word_++];
    const long line = this->line();
    if (is_integral(type)) return static_cast<double>(parse_integer(word, file_, line, "integer"));
    return parse_real(word, file_, line, "number");
  }

  void end() {
    if (next_word_ != words_.size())
      fail(fmt::format("{} values on this line, expected {}", words_.size(), next_word_));
  }

  [[nodiscard]] long line() const { return first_line_ + cursor_.line_number(); }
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(located_message(file_, line(), message));
  }

 private:
  LineCursor cursor_;
  long first_line_;
  const std::string& file_;
  std::vector<std::string_view> words_;
  std::size_t next_word_ = 0;
};

/// The values of the data section as raw bytes in a given byte order. Errors name the
/// element instance, since binary data has no lines.
class PlyBinaryValues {
 public:
  PlyBinaryValues(std::string_view data, bool swap_bytes, const std::string& file)
      : data_(data), swap_bytes_(swap_bytes), file_(file) {}

  void begin(const PlyElement& element, int index) {
    element_ = &element;
    index_ = index;
  }

  double read(PlyScalar type) {
    const std::size_t size = size_of(type);
    if (data_.size() - offset_ < size)
      fail(fmt::format("truncated file: the data ends {} bytes into the data section",
                       data_.size()));
    std::array<char, 8> bytes{};
    std::memcpy(bytes.data(), data_.data() + offset_, size);
    offset_ += size;
    if (swap_bytes_) std::reverse(bytes.begin(), bytes.begin() + static_cast<long>(size));
    switch (type) {
      case PlyScalar::int8: return decode<std::int8_t>(bytes);
      case PlyScalar::uint8: return decode<std::uint8_t>(bytes);
      case PlyScalar::int16: return decode<std::int16_t>(bytes);
      case PlyScalar::uint16: return decode<std::uint16_t>(bytes);
      case PlyScalar::int32: return decode<std::int32_t>(bytes);
      case PlyScalar::uint32: return decode<std::uint32_t>(bytes);
      case PlyScalar::float32: return decode<float>(bytes);
      case PlyScalar::float64: return decode<double>(bytes);
    }
    return 0;
  }

  void end() {}

  /// Binary data has no lines; 0 makes later errors name the element index only.
  [[nodiscard]] long line() const { return 0; }

  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(
        located_message(file_, 0, fmt::format("{} {}: {}", element_->name, index_, message)));
  }

 private:
  template <class T>
  static double decode(const std::array<char, 8>& bytes) {
    T value;
    std::memcpy(&value, bytes.data(), sizeof(T));
    return static_cast<double>(value);
  }

  std::string_view data_;
  std::size_t offset_ = 0;
  bool swap_bytes_;
  const std::string& file_;
  const PlyElement* element_ = nullptr;
  int index_ = 0;
};

/// Reads every element instance from `values`, keeping vertex positions and face triangles.
template <class Values>
void read_elements(const PlyHeader& header, const PlyLayout& layout, Values& values,
                   MeshBuilder& builder) {
  std::vector<double> scalars;
  for (const PlyElement& element : header.elements) {
    // Instances without properties occupy no data at all.
    if (element.properties.empty()) continue;
    const bool is_vertex = element.name == "vertex";
    const bool is_face = element.name == "face";
    scalars.resize(element.properties.size());
    for (int i = 0; i < element.count; ++i) {
      values.begin(element, i);
      std::array<int, 3> corners{};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (!property.list_count) {
          scalars[p] = values.read(property.type);
          continue;
        }
        const double count = values.read(*property.list_count);
        const bool is_index_list = is_face && static_cast<int>(p) == layout.face_indices;
        if (is_index_list && count != 3)
          values.fail(
              fmt::format("face {} has {} vertices; only triangles are supported "
                          "(triangulate the mesh)",
                          i, count));
        if (count < 0) values.fail(fmt::format("negative list length {}", count));
        for (double k = 0; k < count; ++k) {
          const double item = values.read(property.type);
          if (!is_index_list) continue;
          if (!(item >= 0 && item < INT_MAX))
            values.fail(fmt::format("face index {} is out of range", item));
          corners[static_cast<std::size_t>(k)] = static_cast<int>(item);
        }
      }
      values.end();
      if (is_vertex)
        builder.add_vertex(scalars[layout.xyz[0]], scalars[layout.xyz[1]], scalars[layout.xyz[2]],
                           values.line());
      else if (is_face)
        builder.add_triangle(corners[0], corners[1], corners[2], values.line());
    }
  }
}

void write_little_endian(std::ostream& out, const void* value, std::size_t size) {
  std::array<char, 8> bytes{};
  std::memcpy(bytes.data(), value, size);
  if constexpr (std::endian::native == std::endian::big)
    std::reverse(bytes.begin(), bytes.begin() + static_cast<long>(size));
  out.write(bytes.data(), static_cast<std::streamsize>(size));
}

}  // namespace

ParsedMesh parse_ply(std::string_view bytes, const std::string& file) {
  const PlyHeader header = PlyHeaderParser(bytes, file).parse();
  const PlyLayout layout = find_layout(header, file);
  const std::string_view data = bytes.substr(header.data_offset);
  MeshBuilder builder;
  if (header.encoding == PlyEncoding::ascii) {
    PlyAsciiValues values(data, header.data_line, file);
    read_elements(header, layout, values, builder);
    return builder.finish(file, 0);
  }
  const std::endian file_order =
      header.encoding == PlyEncoding::little_endian ? std::endian::little : std::endian::big;
  PlyBinaryValues values(data, file_order != std::endian::native, file);
  read_elements(header, layout, values, builder);
  return builder.finish(file, 0);
}

void write_ply(std::ostream& out, const TriMesh& mesh) {
  out << fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment written by psq\n"
      "element vertex {}\nproperty double x\nproperty double y\nproperty double z\n"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      mesh.vertex_count(), mesh.triangle_count());
  for (int v = 0; v < mesh.vertex_count(); ++v)
    for (int axis = 0; axis < 3; ++axis) write_little_endian(out, &mesh.vertices(v, axis), 8);
  const std::uint8_t corners = 3;
  for (int f = 0; f < mesh.triangle_count(); ++f) {
    write_little_endian(out, &corners, 1);
    for (int k = 0; k < 3; ++k) write_little_endian(out, &mesh.triangles(f, k), 4);
  }
}

}  // namespace psq
