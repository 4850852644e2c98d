#include "engine/io/xdmf.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <functional>
#include <ostream>
#include <set>
#include <string_view>
#include <utility>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"

namespace psq {
namespace {

std::string escape_xml(std::string_view text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

/// A DataItem reading an n×3 dataset of part `part` of an entry's file; `number` is the XDMF
/// NumberType and `precision` its size in bytes, matching what write_part_meshes stores.
std::string hdf_item(const XdmfEntry& entry, std::size_t part, std::string_view dataset,
                     Eigen::Index rows, std::string_view number, int precision) {
  return fmt::format(
      "<DataItem Dimensions=\"{} 3\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">{}:{}/{}"
      "</DataItem>",
      rows, number, precision, escape_xml(entry.file), part_mesh_layout::group(part), dataset);
}

/// A grid-centred attribute (ParaView shows it as field data) holding one inline value.
std::string grid_value(std::string_view indent, std::string_view name, std::string_view number,
                       int precision, const std::string& value) {
  return fmt::format(
      "{0}<Attribute Name=\"{1}\" AttributeType=\"Scalar\" Center=\"Grid\">\n"
      "{0}  <DataItem Dimensions=\"1\" NumberType=\"{2}\" Precision=\"{3}\" Format=\"XML\">{4}"
      "</DataItem>\n"
      "{0}</Attribute>\n",
      indent, name, number, precision, value);
}

std::string node_vector(const XdmfEntry& entry, std::size_t part, std::string_view indent,
                        std::string_view name, std::string_view dataset) {
  return fmt::format(
      "{0}<Attribute Name=\"{1}\" AttributeType=\"Vector\" Center=\"Node\">\n"
      "{0}  {2}\n"
      "{0}</Attribute>\n",
      indent, name, hdf_item(entry, part, dataset, entry.parts[part].vertex_count, "Float", 8));
}

/// The topology, geometry and node vectors of part `part` of `entry`, indented by `indent`.
std::string part_mesh(const XdmfEntry& entry, std::size_t part, std::string_view indent) {
  const XdmfPart& p = entry.parts[part];
  return fmt::format(
             "{0}<Topology TopologyType=\"Triangle\" NumberOfElements=\"{1}\">\n"
             "{0}  {2}\n"
             "{0}</Topology>\n"
             "{0}<Geometry GeometryType=\"XYZ\">\n"
             "{0}  {3}\n"
             "{0}</Geometry>\n",
             indent, p.triangle_count,
             hdf_item(entry, part, part_mesh_layout::triangles, p.triangle_count, "Int", 4),
             hdf_item(entry, part, part_mesh_layout::positions, p.vertex_count, "Float", 8)) +
         node_vector(entry, part, indent, "rest_position", part_mesh_layout::rest_positions) +
         node_vector(entry, part, indent, "displacement", part_mesh_layout::displacement);
}

std::string step_name(const XdmfEntry& entry) {
  return fmt::format("level{}_frame{}", entry.level, entry.frame);
}

/// Step `step` of the ParaView sidecar: a spatial collection of every part's grid.
void write_step(std::ostream& out, const XdmfEntry& entry, std::size_t step) {
  out << fmt::format(
             "      <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n",
             step_name(entry))
      << fmt::format("        <Time Value=\"{}\"/>\n", step);
  constexpr std::string_view indent = "          ";
  for (std::size_t part = 0; part < entry.parts.size(); ++part)
    out << fmt::format("        <Grid Name=\"{}\" GridType=\"Uniform\">\n",
                       escape_xml(entry.parts[part].name))
        << part_mesh(entry, part, indent)
        << grid_value(indent, "level", "Int", 4, std::to_string(entry.level))
        << grid_value(indent, "frame", "Int", 4, std::to_string(entry.frame))
        << grid_value(indent, "time", "Float", 8, fmt::format("{}", entry.time))
        << "        </Grid>\n";
  out << "      </Grid>\n";
}

/// Step `step` of part `part`'s own sidecar: that part's grid alone.
void write_part_step(std::ostream& out, const XdmfEntry& entry, std::size_t part,
                     std::size_t step) {
  out << fmt::format("      <Grid Name=\"{}\" GridType=\"Uniform\">\n", step_name(entry))
      << fmt::format("        <Time Value=\"{}\"/>\n", step) << part_mesh(entry, part, "        ")
      << "      </Grid>\n";
}

/// Writes an XDMF file holding one temporal collection named `name`, its steps by `write_steps`.
void write_time_series(const std::filesystem::path& path, std::string_view name,
                       const std::function<void(std::ostream&)>& write_steps) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
        << "<Xdmf Version=\"3.0\">\n"
        << "  <Domain>\n"
        << fmt::format(
               "    <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
               escape_xml(name));
    write_steps(out);
    out << "    </Grid>\n"
        << "  </Domain>\n"
        << "</Xdmf>\n";
  });
}

[[noreturn]] void reject(const std::filesystem::path& path, const XdmfEntry& entry,
                         std::string_view problem) {
  throw InputError(located_message(path.string(), 0,
                                   fmt::format("part meshes '{}' (level {}, frame {}): {}",
                                               entry.file, entry.level, entry.frame, problem)));
}

void check_entry(const std::filesystem::path& path, const XdmfEntry& entry,
                 const XdmfEntry& first) {
  if (entry.file.empty()) reject(path, entry, "empty file name");
  if (entry.file.find(':') != std::string::npos)
    reject(path, entry, "file names with ':' cannot be referenced from XDMF");
  for (const XdmfPart& part : entry.parts)
    if (part.vertex_count < 0 || part.triangle_count < 0)
      reject(path, entry, fmt::format("part '{}': negative vertex or triangle count", part.name));
  const auto same_name = [](const XdmfPart& a, const XdmfPart& b) { return a.name == b.name; };
  if (!std::equal(entry.parts.begin(), entry.parts.end(), first.parts.begin(), first.parts.end(),
                  same_name))
    reject(path, entry,
           fmt::format("its parts differ from those of '{}': every step of a time series shows "
                       "the same parts in the same order",
                       first.file));
}

std::string file_name_part(std::string_view name) {
  std::string safe(name);
  for (char& c : safe)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return safe;
}

}  // namespace

XdmfEntry xdmf_entry(std::string file, const PartMeshes& meshes) {
  XdmfEntry entry{.file = std::move(file),
                  .level = meshes.level,
                  .frame = meshes.frame,
                  .time = meshes.time,
                  .parts = {}};
  for (const PartMesh& part : meshes.parts)
    entry.parts.push_back({part.name, part.positions.rows(), part.triangles.rows()});
  return entry;
}

std::vector<std::filesystem::path> part_sidecar_paths(const std::filesystem::path& path,
                                                      const std::vector<std::string>& part_names) {
  std::vector<std::filesystem::path> paths;
  std::set<std::string> taken;
  for (std::size_t k = 0; k < part_names.size(); ++k) {
    std::string name = file_name_part(part_names[k]);
    while (taken.contains(name)) name += fmt::format("_{}", k);
    taken.insert(name);
    paths.push_back(path.parent_path() / fmt::format("{}.{}.xdmf", path.stem().string(), name));
  }
  return paths;
}

void write_xdmf(const std::filesystem::path& path, const std::vector<XdmfEntry>& entries) {
  for (const XdmfEntry& entry : entries) check_entry(path, entry, entries.front());
  std::vector<std::string> part_names;
  if (!entries.empty())
    for (const XdmfPart& part : entries.front().parts) part_names.push_back(part.name);
  const std::vector<std::filesystem::path> part_paths = part_sidecar_paths(path, part_names);
  for (std::size_t part = 0; part < part_paths.size(); ++part)
    write_time_series(part_paths[part], part_names[part], [&](std::ostream& out) {
      for (std::size_t step = 0; step < entries.size(); ++step)
        write_part_step(out, entries[step], part, step);
    });
  write_time_series(path, "levels", [&](std::ostream& out) {
    for (std::size_t step = 0; step < entries.size(); ++step) write_step(out, entries[step], step);
  });
}

}  // namespace psq
