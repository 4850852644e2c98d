#pragma once
// XDMF 3 sidecars: small XML files beside a job's part meshes (engine/io/part_meshes.hpp) that
// let ParaView (or VisIt) open all of its levels as one time series with one block per shell
// and collider, and let readers that take one mesh per time series (meshio) open each part on
// its own. The meshes are read from the HDF5 files. Layout: docs/checkpoint-format.md.

#include <filesystem>
#include <string>
#include <vector>

#include "engine/io/part_meshes.hpp"

namespace psq {

/// One part of an entry: what its grid declares.
struct XdmfPart {
  std::string name;
  Eigen::Index vertex_count = 0;
  Eigen::Index triangle_count = 0;
};

/// One part-meshes file as listed in a sidecar: one time step.
struct XdmfEntry {
  std::string file;  ///< part-meshes path, relative to the sidecar's directory (or absolute)
  int level = 0;
  int frame = 0;
  double time = 0.0;  ///< simulated time, seconds
  std::vector<XdmfPart> parts;
};

/// The entry for `meshes` stored at `file` (relative to the sidecar's directory).
XdmfEntry xdmf_entry(std::string file, const PartMeshes& meshes);

/// The per-part sidecars write_xdmf writes beside `path` for parts named `part_names` (in
/// order): `<stem>.<name>.xdmf`, the name with characters other than letters, digits, '-' and
/// '_' replaced by '_', and `_<index>` appended when that name is taken already.
std::vector<std::filesystem::path> part_sidecar_paths(const std::filesystem::path& path,
                                                      const std::vector<std::string>& part_names);

/// Writes the sidecar `path` and the per-part sidecars beside it (part_sidecar_paths), each
/// atomically. `path` holds a temporal collection with one spatial collection per entry, in
/// the given order, of one uniform grid per part named after it: triangle topology, XYZ
/// geometry, the node vectors "rest_position" and "displacement", and level, frame and
/// simulated time as grid (field) values. A per-part sidecar holds a temporal collection of that
/// part's uniform grids alone, without the grid values (meshio refuses grid-centred attributes).
/// The time of entry k is k, not the simulated time: the levels of a progressive solve share
/// the time of their refine frame, and a time series needs distinct times. Throws InputError
/// naming `path` if a file cannot be written, if an entry's file name contains ':' (the XDMF
/// separator of file and dataset) or is empty, or if the entries' parts differ in names or order.
void write_xdmf(const std::filesystem::path& path, const std::vector<XdmfEntry>& entries);

}  // namespace psq
