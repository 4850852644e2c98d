#include "engine/mesh/mesh_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "engine/core/input_file.hpp"
#include "engine/mesh/mesh_io_formats.hpp"

namespace psq {
namespace {

enum class MeshFormat { obj, ply, off };

MeshFormat format_of(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".obj") return MeshFormat::obj;
  if (extension == ".ply") return MeshFormat::ply;
  if (extension == ".off") return MeshFormat::off;
  throw InputError(located_message(
      path.string(), 0,
      fmt::format("unknown mesh file extension '{}'; use .obj, .ply or .off", extension)));
}

}  // namespace

TriMesh read_mesh(const std::filesystem::path& path) {
  const std::string file = path.string();
  const MeshFormat format = format_of(path);
  const std::string bytes = read_input_file(path, "mesh file");
  ParsedMesh parsed;
  switch (format) {
    case MeshFormat::obj: parsed = parse_obj(bytes, file); break;
    case MeshFormat::ply: parsed = parse_ply(bytes, file); break;
    case MeshFormat::off: parsed = parse_off(bytes, file); break;
  }
  check_mesh(parsed.mesh, parsed.origin);
  return std::move(parsed.mesh);
}

void write_mesh(const std::filesystem::path& path, const TriMesh& mesh) {
  const MeshFormat format = format_of(path);
  if (!mesh.vertices.allFinite())
    throw NumericalError(
        fmt::format("refusing to write '{}': the mesh has non-finite coordinates", path.string()));
  write_file_atomically(path, [&](std::ostream& out) {
    switch (format) {
      case MeshFormat::obj: write_obj(out, mesh); break;
      case MeshFormat::ply: write_ply(out, mesh); break;
      case MeshFormat::off: write_off(out, mesh); break;
    }
  });
}

}  // namespace psq
