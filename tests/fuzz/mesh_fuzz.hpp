#pragma once
// The body shared by the mesh-reader fuzz targets: what read_mesh does once it holds a file's
// bytes (parse, then check_mesh), without the file system. InputError is the documented
// answer to a bad file and is swallowed; any other exception escapes to libFuzzer, which
// reports it as a crash, as it does sanitizer reports, aborts, timeouts and memory blow-ups.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io_formats.hpp"

namespace psq::fuzz {

/// `parse` reads the input; an accepted mesh must also survive `write` and a second `parse`
/// unchanged, since the writers promise an exact round trip and a mesh the reader accepts
/// is one a user may write back out.
template <class Parse, class Write>
int read_mesh_bytes(const std::uint8_t* data, std::size_t size, Parse parse, Write write) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string source = "fuzz input";
  ParsedMesh parsed;
  try {
    parsed = parse(bytes, source);
    check_mesh(parsed.mesh, parsed.origin);
  } catch (const InputError&) {
    return 0;
  }
  std::ostringstream written;
  write(written, parsed.mesh);
  const ParsedMesh reread = parse(written.str(), source);
  // abort() is what libFuzzer reports with the input that caused it.
  if (reread.mesh.vertices != parsed.mesh.vertices ||
      reread.mesh.triangles != parsed.mesh.triangles)
    std::abort();
  return 0;
}

}  // namespace psq::fuzz
