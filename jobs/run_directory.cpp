#include "jobs/run_directory.hpp"

#include <fmt/format.h>

#include <system_error>

#include "engine/core/checksum.hpp"
#include "engine/core/error.hpp"

namespace psq::jobs {
namespace fs = std::filesystem;

fs::path RunDirectory::level_checkpoint(int level) const {
  return dir_ / fmt::format("level_{}.h5", level);
}

fs::path RunDirectory::snapshot(int level) const {
  return dir_ / fmt::format("level_{}.snapshot.h5", level);
}

fs::path RunDirectory::previous_snapshot(int level) const {
  return dir_ / fmt::format("level_{}.snapshot.prev.h5", level);
}

fs::path RunDirectory::part_meshes(int level) const {
  return dir_ / fmt::format("level_{}.parts.h5", level);
}

fs::path RunDirectory::sidecar() const { return dir_ / "job.xdmf"; }

void RunDirectory::create() const {
  std::error_code error;
  fs::create_directories(dir_, error);
  if (error || !fs::is_directory(dir_))
    throw InputError(
        fmt::format("cannot create the job's output directory '{}': {}; make the "
                    "runs directory beside the job store writable",
                    dir_.string(), error ? error.message() : "not a directory"));
}

void RunDirectory::remove_stale_temporaries() const {
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir_, error)) {
    const std::string name = entry.path().filename().string();
    // replace_file_atomically's temporaries: ".<name>.tmp<pid>".
    if (name.starts_with('.') && name.find(".tmp") != std::string::npos) {
      std::error_code ignored;
      fs::remove(entry.path(), ignored);
    }
  }
}

void RunDirectory::remove_snapshots(int level) const {
  std::error_code ignored;
  fs::remove(snapshot(level), ignored);
  fs::remove(previous_snapshot(level), ignored);
}

std::vector<ResumeCandidate> resume_candidates(const RunDirectory& run, int depth,
                                               const std::vector<db::LevelRecord>& records) {
  std::vector<ResumeCandidate> candidates;
  for (int level = depth - 1; level >= 0; --level) {
    const db::LevelRecord* record = nullptr;
    for (const db::LevelRecord& r : records)
      if (r.level == level) record = &r;
    for (const fs::path& file :
         {run.level_checkpoint(level), run.snapshot(level), run.previous_snapshot(level)}) {
      if (!fs::exists(file)) continue;
      ResumeCandidate candidate{file, std::nullopt};
      if (record && fs::path(record->checkpoint_path).filename() == file.filename())
        candidate.recorded_checksum = parse_checksum(record->checkpoint_checksum);
      candidates.push_back(std::move(candidate));
    }
  }
  return candidates;
}

}  // namespace psq::jobs
