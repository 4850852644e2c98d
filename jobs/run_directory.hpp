#pragma once
// The files of one job run, `<runs>/<job id>/`: a checkpoint and a part-meshes file per finished
// level, the in-level snapshots of the level in progress, and the XDMF sidecars. Which checkpoint a
// resumed job continues from is decided here.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "db/job_records.hpp"

namespace psq::jobs {

/// The names inside a job's run directory.
class RunDirectory {
 public:
  explicit RunDirectory(std::filesystem::path dir) : dir_(std::move(dir)) {}

  const std::filesystem::path& dir() const { return dir_; }
  /// `level_<l>.h5`: the state at the end of level l.
  std::filesystem::path level_checkpoint(int level) const;
  /// `level_<l>.snapshot.h5`: the latest in-level snapshot of level l.
  std::filesystem::path snapshot(int level) const;
  /// `level_<l>.snapshot.prev.h5`: the snapshot before it, kept in case the latest is damaged.
  std::filesystem::path previous_snapshot(int level) const;
  /// `level_<l>.parts.h5`: level l's final state cut into its shells and colliders, shown by
  /// the sidecars.
  std::filesystem::path part_meshes(int level) const;
  /// `job.xdmf`: the ParaView sidecar listing the finished levels (the per-part sidecars
  /// `job.<part>.xdmf` lie beside it).
  std::filesystem::path sidecar() const;

  /// Creates the directory (and its parents). Throws InputError naming it if that fails.
  void create() const;
  /// Removes the temporaries that a process killed while writing a file left behind.
  void remove_stale_temporaries() const;
  /// Removes level l's snapshots (once its final checkpoint is recorded).
  void remove_snapshots(int level) const;

 private:
  std::filesystem::path dir_;
};

/// A checkpoint file a resumed job may continue from, and the file checksum the store
/// recorded for it (none when the store's record of its level names another file: it was
/// written after the last record, or it is the previous snapshot).
struct ResumeCandidate {
  std::filesystem::path file;
  std::optional<std::uint64_t> recorded_checksum;
};

/// The checkpoints to try, most advanced first: for each level from the finest down, its final
/// checkpoint, its latest snapshot and the snapshot before; only existing files. The first
/// that reads back and verifies is the one to continue from; if none does, the job starts
/// over.
std::vector<ResumeCandidate> resume_candidates(const RunDirectory& run, int depth,
                                               const std::vector<db::LevelRecord>& records);

}  // namespace psq::jobs
