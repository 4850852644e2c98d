#include "jobs/run_directory.hpp"

#include <fmt/format.h>

#include <charconv>
#include <string_view>
#include <system_error>

#include "engine/core/error.hpp"

namespace psq::jobs {
namespace fs = std::filesystem;

namespace {
constexpr std::string_view kChecksumPrefix = "fnv1a64:";
}  // namespace

fs::path RunDirectory::level_checkpoint(int level) const {
  return dir_ / fmt::format("level_{}.h5", level);
}

fs::path RunDirectory::snapshot(int level) const {
  return dir_ / fmt::format("level_{}.snapshot.h5", level);
}

fs::path RunDirectory::previous_snapshot(int level) const {
  return dir_ / fmt::format("level_{}.snapshot.prev.h5", level);
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

std::string checksum_text(std::uint64_t checksum) {
  return fmt::format("{}{:016x}", kChecksumPrefix, checksum);
}

std::optional<std::uint64_t> parse_checksum(const std::string& text) {
  if (!text.starts_with(kChecksumPrefix)) return std::nullopt;
  const std::string_view digits = std::string_view(text).substr(kChecksumPrefix.size());
  std::uint64_t value = 0;
  const auto [end, error] =
      std::from_chars(digits.data(), digits.data() + digits.size(), value, 16);
  if (error != std::errc() || end != digits.data() + digits.size() || digits.size() != 16)
    return std::nullopt;
  return value;
}

}  // namespace psq::jobs
