#pragma once
// XDMF 3 sidecars: a small XML file beside a job's checkpoints that lets ParaView (or VisIt)
// open all of its levels and frames as one time series, reading the meshes from the HDF5 files.

#include <filesystem>
#include <string>
#include <vector>

#include "engine/io/checkpoint.hpp"

namespace psq {

/// One checkpoint as listed in a sidecar.
struct XdmfEntry {
  std::string file;  ///< checkpoint path, relative to the sidecar's directory (or absolute)
  int level = 0;
  int frame = 0;
  double time = 0.0;  ///< simulated time, seconds
  Eigen::Index vertex_count = 0;
  Eigen::Index triangle_count = 0;
};

/// The entry for `checkpoint` stored at `file` (relative to the sidecar's directory).
XdmfEntry xdmf_entry(std::string file, const Checkpoint& checkpoint);

/// Writes an XDMF 3 file whose temporal collection holds one grid per entry, in the given order:
/// triangle topology from the checkpoint's triangles, XYZ geometry from its positions, the rest
/// positions as a node vector "rest_position", and level, frame and simulated time as grid
/// (field) values. The collection's time of entry k is k, not the simulated time: the levels of
/// a progressive solve share the time of their refine frame, and a time series needs distinct
/// times. Written atomically. Throws InputError naming `path` if it cannot be written, or if an
/// entry's file name contains ':' (the XDMF separator of file and dataset) or is empty.
void write_xdmf(const std::filesystem::path& path, const std::vector<XdmfEntry>& entries);

}  // namespace psq
