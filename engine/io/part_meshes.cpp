#include "engine/io/part_meshes.hpp"

#include <fmt/format.h>

#include <array>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <utility>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "engine/core/input_file.hpp"
#include "engine/io/hdf5_handle.hpp"

namespace psq {
namespace {

/// Value of the root attribute "format" that marks a file as PSQ part meshes.
constexpr std::string_view format_marker = "psq-part-meshes";
constexpr int schema_version = 1;

constexpr std::array kind_names{std::pair{PartKind::shell, "shell"},
                                std::pair{PartKind::collider, "collider"}};

std::string_view kind_name(PartKind kind) {
  for (const auto& [k, name] : kind_names)
    if (k == kind) return name;
  throw std::logic_error("kind_name: unknown part kind");
}

std::optional<PartKind> parse_kind(std::string_view name) {
  for (const auto& [kind, n] : kind_names)
    if (n == name) return kind;
  return std::nullopt;
}

[[noreturn]] void fail(const std::string& file, std::string_view problem) {
  throw InputError(located_message(file, 0, std::string(problem)));
}

PartMesh split_part(const Positions& positions, const TriMesh& rest, const PartRange& range) {
  const bool vertices_inside = range.first_vertex >= 0 && range.vertex_count >= 0 &&
                               range.first_vertex + range.vertex_count <= rest.vertex_count() &&
                               rest.vertex_count() == positions.rows();
  const bool triangles_inside =
      range.first_triangle >= 0 && range.triangle_count >= 0 &&
      range.first_triangle + range.triangle_count <= rest.triangle_count();
  if (!vertices_inside || !triangles_inside)
    throw std::invalid_argument(fmt::format(
        "split_into_parts: part '{}' (vertices {}+{}, triangles {}+{}) lies outside "
        "the system's {} vertices and {} triangles ({} positions)",
        range.name, range.first_vertex, range.vertex_count, range.first_triangle,
        range.triangle_count, rest.vertex_count(), rest.triangle_count(), positions.rows()));
  PartMesh part{
      .name = range.name,
      .kind = range.kind,
      .positions = positions.middleRows(range.first_vertex, range.vertex_count),
      .rest_positions = rest.vertices.middleRows(range.first_vertex, range.vertex_count),
      .triangles = rest.triangles.middleRows(range.first_triangle, range.triangle_count).array() -
                   range.first_vertex};
  if (part.triangles.size() > 0 &&
      (part.triangles.minCoeff() < 0 || part.triangles.maxCoeff() >= range.vertex_count))
    throw std::invalid_argument(fmt::format(
        "split_into_parts: a triangle of part '{}' uses a vertex of another part", range.name));
  return part;
}

/// Why `part` cannot be written, if it cannot.
std::optional<std::string> inconsistency(const PartMesh& part) {
  if (part.name.empty()) return "a part without a name";
  const Eigen::Index n = part.positions.rows();
  if (part.rest_positions.rows() != n)
    return fmt::format("part '{}' has {} positions but {} rest positions", part.name, n,
                       part.rest_positions.rows());
  if (part.triangles.size() > 0 &&
      (part.triangles.minCoeff() < 0 || part.triangles.maxCoeff() >= n))
    return fmt::format("part '{}' has a triangle index outside [0, {})", part.name, n);
  return std::nullopt;
}

void encode(const PartMeshes& meshes, const std::filesystem::path& path) {
  hdf5::File file = hdf5::File::create(path);
  hdf5::Group& root = file.root();
  root.write_attribute("format", format_marker);
  root.write_attribute("schema_version", schema_version);
  root.write_attribute("level", meshes.level);
  root.write_attribute("frame", meshes.frame);
  root.write_attribute("time", meshes.time);
  root.write_attribute("part_count", static_cast<std::int32_t>(meshes.parts.size()));
  root.create_group("parts");
  for (std::size_t k = 0; k < meshes.parts.size(); ++k) {
    const PartMesh& part = meshes.parts[k];
    hdf5::Group group = root.create_group(part_mesh_layout::group(k));
    group.write_attribute("name", part.name);
    group.write_attribute("kind", kind_name(part.kind));
    hdf5::write_rows(group, part_mesh_layout::positions, part.positions);
    hdf5::write_rows(group, part_mesh_layout::rest_positions, part.rest_positions);
    const Positions displacement = part.positions - part.rest_positions;
    hdf5::write_rows(group, part_mesh_layout::displacement, displacement);
    hdf5::write_rows(group, part_mesh_layout::triangles, part.triangles);
  }
  file.close();
}

PartMesh decode_part(const hdf5::Group& root, std::size_t k) {
  const hdf5::Group group = root.open_group(part_mesh_layout::group(k));
  const std::string kind = group.read_string_attribute("kind");
  const std::optional<PartKind> parsed = parse_kind(kind);
  if (!parsed)
    fail(root.file_name(), fmt::format("{}: unknown part kind '{}'", group.path(), kind));
  PartMesh part{
      .name = group.read_string_attribute("name"),
      .kind = *parsed,
      .positions = hdf5::read_rows<Positions>(group, part_mesh_layout::positions),
      .rest_positions = hdf5::read_rows<Positions>(group, part_mesh_layout::rest_positions),
      .triangles = hdf5::read_rows<Triangles>(group, part_mesh_layout::triangles)};
  if (const auto problem = inconsistency(part)) fail(root.file_name(), *problem);
  return part;
}

PartMeshes decode(const std::string& file_name, std::span<const char> bytes) {
  const hdf5::File file = hdf5::File::open_image(file_name, bytes);
  const hdf5::Group& root = file.root();
  if (!root.has_attribute("format") || root.read_string_attribute("format") != format_marker)
    fail(file_name, fmt::format("not a PSQ part-meshes file (no root attribute format = \"{}\")",
                                format_marker));
  if (const int version = root.read_attribute<std::int32_t>("schema_version");
      version != schema_version)
    fail(file_name, fmt::format("part-meshes schema version {}; this program reads version {}",
                                version, schema_version));
  PartMeshes meshes{.level = root.read_attribute<std::int32_t>("level"),
                    .frame = root.read_attribute<std::int32_t>("frame"),
                    .time = root.read_attribute<double>("time"),
                    .parts = {}};
  const int count = root.read_attribute<std::int32_t>("part_count");
  if (count < 0) fail(file_name, fmt::format("negative part_count {}", count));
  for (int k = 0; k < count; ++k) meshes.parts.push_back(decode_part(root, k));
  return meshes;
}

}  // namespace

std::string part_mesh_layout::group(std::size_t part) { return fmt::format("/parts/{}", part); }

std::vector<PartMesh> split_into_parts(const Positions& positions, const TriMesh& rest,
                                       const std::vector<PartRange>& ranges) {
  std::vector<PartMesh> parts;
  for (const PartRange& range : ranges) parts.push_back(split_part(positions, rest, range));
  return parts;
}

void write_part_meshes(const std::filesystem::path& path, const PartMeshes& meshes) {
  for (const PartMesh& part : meshes.parts)
    if (const auto problem = inconsistency(part))
      fail(path.string(), fmt::format("refusing to write inconsistent part meshes: {}", *problem));
  try {
    replace_file_atomically(path, [&](const std::filesystem::path& temporary) {
      const std::lock_guard lock(hdf5::library_mutex());
      encode(meshes, temporary);
    });
  } catch (const hdf5::Hdf5Error& e) {
    // HDF5 errors name the temporary file; the caller knows the file by its final name.
    fail(path.string(), fmt::format("cannot write part meshes: {}", e.what()));
  }
}

PartMeshes read_part_meshes(const std::filesystem::path& path) {
  const std::string bytes = read_input_file(path, "part-meshes file");
  try {
    const std::lock_guard lock(hdf5::library_mutex());
    return decode(path.string(), std::span(bytes.data(), bytes.size()));
  } catch (const hdf5::Hdf5Error& e) {
    fail(path.string(), fmt::format("damaged or not a part-meshes file: {}", e.what()));
  }
}

}  // namespace psq
