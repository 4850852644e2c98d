#include "engine/io/xdmf.hpp"

#include <fmt/format.h>

#include <ostream>
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

/// A DataItem reading an n×3 dataset of a checkpoint; `number` is the XDMF NumberType and
/// `precision` its size in bytes, matching what write_checkpoint stores.
std::string hdf_item(const XdmfEntry& entry, std::string_view dataset, Eigen::Index rows,
                     std::string_view number, int precision) {
  return fmt::format(
      "<DataItem Dimensions=\"{} 3\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">{}:{}"
      "</DataItem>",
      rows, number, precision, escape_xml(entry.file), dataset);
}

/// A grid-centred attribute (ParaView shows it as field data) holding one inline value.
std::string grid_value(std::string_view name, std::string_view number, int precision,
                       const std::string& value) {
  return fmt::format(
      "        <Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Grid\">\n"
      "          <DataItem Dimensions=\"1\" NumberType=\"{}\" Precision=\"{}\" Format=\"XML\">{}"
      "</DataItem>\n"
      "        </Attribute>\n",
      name, number, precision, value);
}

void write_grid(std::ostream& out, const XdmfEntry& entry, std::size_t step) {
  out << fmt::format("      <Grid Name=\"level{}_frame{}\" GridType=\"Uniform\">\n", entry.level,
                     entry.frame)
      << fmt::format("        <Time Value=\"{}\"/>\n", step)
      << fmt::format("        <Topology TopologyType=\"Triangle\" NumberOfElements=\"{}\">\n",
                     entry.triangle_count)
      << "          "
      << hdf_item(entry, checkpoint_layout::triangles, entry.triangle_count, "Int", 4) << "\n"
      << "        </Topology>\n"
      << "        <Geometry GeometryType=\"XYZ\">\n"
      << "          "
      << hdf_item(entry, checkpoint_layout::positions, entry.vertex_count, "Float", 8) << "\n"
      << "        </Geometry>\n"
      << "        <Attribute Name=\"rest_position\" AttributeType=\"Vector\" Center=\"Node\">\n"
      << "          "
      << hdf_item(entry, checkpoint_layout::rest_positions, entry.vertex_count, "Float", 8)
      << "\n"
      << "        </Attribute>\n"
      << grid_value("level", "Int", 4, std::to_string(entry.level))
      << grid_value("frame", "Int", 4, std::to_string(entry.frame))
      << grid_value("time", "Float", 8, fmt::format("{}", entry.time)) << "      </Grid>\n";
}

void check_entry(const std::filesystem::path& path, const XdmfEntry& entry) {
  auto reject = [&](std::string_view problem) {
    throw InputError(located_message(
        path.string(), 0, fmt::format("checkpoint '{}' (level {}, frame {}): {}", entry.file,
                                      entry.level, entry.frame, problem)));
  };
  if (entry.file.empty()) reject("empty file name");
  if (entry.file.find(':') != std::string::npos)
    reject("file names with ':' cannot be referenced from XDMF");
  if (entry.vertex_count < 0 || entry.triangle_count < 0)
    reject("negative vertex or triangle count");
}

}  // namespace

XdmfEntry xdmf_entry(std::string file, const Checkpoint& checkpoint) {
  return {.file = std::move(file),
          .level = checkpoint.level,
          .frame = checkpoint.frame,
          .time = checkpoint.time,
          .vertex_count = checkpoint.positions.rows(),
          .triangle_count = checkpoint.triangles.rows()};
}

void write_xdmf(const std::filesystem::path& path, const std::vector<XdmfEntry>& entries) {
  for (const XdmfEntry& entry : entries) check_entry(path, entry);
  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
        << "<Xdmf Version=\"3.0\">\n"
        << "  <Domain>\n"
        << "    <Grid Name=\"checkpoints\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (std::size_t step = 0; step < entries.size(); ++step) write_grid(out, entries[step], step);
    out << "    </Grid>\n"
        << "  </Domain>\n"
        << "</Xdmf>\n";
  });
}

}  // namespace psq
