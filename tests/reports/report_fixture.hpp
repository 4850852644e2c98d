#pragma once
// A job store with one sweep of synthetic jobs and their checkpoints, for the report tests
// (tests/reports and tests/runner). Every quantity the report derives has a closed form here:
// each level is a k×k grid on the unit square bent to z = −a·x², and level l's state prolonged
// to the finest mesh is the finest state with vertex 0 lifted by δ_l, so its error to the
// finest level is δ_l / √(2 + a²) and the maximum displacement is a.

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "db/job_store.hpp"
#include "engine/core/checksum.hpp"
#include "engine/io/checkpoint.hpp"
#include "engine/io/part_meshes.hpp"
#include "support/test_paths.hpp"

namespace psq::test {

/// How a level's checkpoint is recorded in the store.
enum class CheckpointCase {
  absolute_path,       ///< written, recorded by absolute path
  workspace_relative,  ///< written, recorded relative to the store's directory
  corrupted,           ///< written, recorded, then damaged on disk
  missing,             ///< recorded, never written
};

/// The static residual the fixture records for level l's one settled frame.
inline double fixture_static_residual(int level) { return 1e-7 * (level + 1); }

struct FixtureLevel {
  db::LevelStatus status = db::LevelStatus::done;
  std::vector<double> residuals;
  std::map<std::string, double> timings;
  double expected_seconds = 0;  ///< what the timings mean (docs/reports.md)
  double lift = 0;              ///< δ_l
  CheckpointCase checkpoint = CheckpointCase::absolute_path;
  std::string error;
  /// Frames with their load scale and probe readings, as the executor records them.
  std::vector<db::FrameReadings> frames = {};
};

struct FixtureJob {
  std::string id;
  double thickness = 0;
  double youngs_modulus = 0;
  db::JobState state = db::JobState::done;  ///< done, failed or queued
  std::string error;
  double bend = 0;  ///< a
  std::optional<double> elastic_energy;
  std::vector<FixtureLevel> levels;  ///< recorded levels; the job's depth is their count
  /// With a collider below the plate (add_collider), and part-meshes files beside its
  /// checkpoints as the executor writes them.
  bool collider = false;
  int depth() const { return static_cast<int>(levels.size()); }
  nlohmann::json parameters() const {
    return {{"depth", depth()},
            {"overrides",
             {{"shell.plate.material.thickness", thickness},
              {"shell.plate.material.youngs_modulus", youngs_modulus}}},
            {"scene", "fnv1a64:00000000000000aa"}};
  }
};

/// Newton-like history: per frame, the residual drops quadratically from `start`.
inline std::vector<double> newton_history(int frames, double start) {
  std::vector<double> residuals;
  for (int f = 0; f < frames; ++f)
    for (double r = start; r > 1e-12; r = r * r / start * 0.1) residuals.push_back(r);
  return residuals;
}

/// The six jobs of the sweep "plates", in the order they are added.
inline std::vector<FixtureJob> fixture_jobs() {
  std::vector<FixtureJob> jobs(6);
  jobs[0] = {"00000000000000a1", 1e-3, 1e6, db::JobState::done, "", 0.2, 0.125, {}, false};
  jobs[0].levels = {
      {db::LevelStatus::done,
       newton_history(2, 1.0),
       {{"assembly", 0.1}, {"solve", 0.2}},
       0.1 + 0.2,
       0.05,
       CheckpointCase::absolute_path,
       ""},
      {db::LevelStatus::done,
       newton_history(1, 0.5),
       {{"wall", 1.5}, {"assembly", 0.4}},
       1.5,
       0.01,
       CheckpointCase::absolute_path,
       ""},
      {db::LevelStatus::done,
       newton_history(1, 0.3),
       {{"total", 6.0}, {"solve", 5.0}},
       6.0,
       0.0,
       CheckpointCase::workspace_relative,
       ""},
  };
  // The finest level's load ramp: a tip probe and a clamp's reaction at s = 1/2, 1.
  jobs[0].levels.back().frames = {
      {1, 0.5, {{"clamp", "reaction", {0, 0, -2}}, {"tip", "displacement", {0, 0, -0.01}}}},
      {2, 1.0, {{"clamp", "reaction", {0, 0, -4}}, {"tip", "displacement", {0, 0, -0.02}}}}};
  // A diverged iteration in the middle: stored as null, skipped when drawn.
  jobs[0].levels[2].residuals.insert(jobs[0].levels[2].residuals.begin() + 2, NAN);
  jobs[1] = {"00000000000000b2", 2e-3, 1e6, db::JobState::done, "", 0.1, std::nullopt, {}, false};
  jobs[1].levels = {
      {db::LevelStatus::done,
       newton_history(3, 2.0),
       {{"wall", 0.25}},
       0.25,
       0.02,
       CheckpointCase::workspace_relative,
       ""},
      {db::LevelStatus::done,
       newton_history(1, 1.0),
       {{"wall", 2.0}},
       2.0,
       0.0,
       CheckpointCase::corrupted,
       ""},
  };
  jobs[2] = {"00000000000000c3", 1e-3, 1e7, db::JobState::done, "", 0.05, 0.5, {}, true};
  jobs[2].levels = {{db::LevelStatus::done,
                     newton_history(4, 0.8),
                     {{"wall", 0.75}},
                     0.75,
                     0.0,
                     CheckpointCase::workspace_relative,
                     ""}};
  jobs[3] = {"00000000000000d4",           2e-3, 1e7,          db::JobState::failed,
             "Newton diverged at frame 3", 0.1,  std::nullopt, {}, false};
  jobs[3].levels = {
      {db::LevelStatus::done,
       newton_history(1, 1.0),
       {{"wall", 0.5}},
       0.5,
       0.03,
       CheckpointCase::absolute_path,
       ""},
      {db::LevelStatus::failed,
       {1.0, 3.0, 40.0},
       {{"wall", 0.1}},
       0.1,
       0.0,
       CheckpointCase::absolute_path,
       "Newton diverged at frame 3"},
  };
  jobs[4] = {"00000000000000e5", 4e-3, 1e7, db::JobState::done, "", 0.1, std::nullopt, {}, false};
  jobs[4].levels = {{db::LevelStatus::done,
                     newton_history(1, 1.0),
                     {{"wall", 0.4}},
                     0.4,
                     0.0,
                     CheckpointCase::missing,
                     ""}};
  jobs[5] = {"00000000000000f6", 4e-3, 1e6, db::JobState::queued, "", 0.1, std::nullopt, {}, false};
  jobs[5].levels = {FixtureLevel{}};
  return jobs;
}

/// The level-l grid: k = 2^(l+1) + 1 vertices a side on the unit square, rest z = 0.
inline void fill_grid(int l, int depth, double bend, double lift, Checkpoint& c) {
  const auto grid = [bend](int k, Positions& rest, Positions& bent, Triangles* triangles) {
    rest.resize(k * k, 3);
    bent.resize(k * k, 3);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        const double x = i / (k - 1.0), y = j / (k - 1.0);
        rest.row(i * k + j) << x, y, 0.0;
        bent.row(i * k + j) << x, y, -bend * x * x;
      }
    if (!triangles) return;
    triangles->resize(2 * (k - 1) * (k - 1), 3);
    int t = 0;
    for (int i = 0; i + 1 < k; ++i)
      for (int j = 0; j + 1 < k; ++j) {
        const int v = i * k + j;
        triangles->row(t++) << v, v + k, v + 1;
        triangles->row(t++) << v + 1, v + k, v + k + 1;
      }
  };
  grid((1 << (l + 1)) + 1, c.rest_positions, c.positions, &c.triangles);
  Positions finest_rest;
  grid((1 << depth) + 1, finest_rest, c.finest_positions, nullptr);
  c.finest_positions(0, 2) += lift;
}

/// The fixture's collider: a horizontal unit square of 2 triangles at z = −1, below the plate,
/// appended to the checkpoint's mesh.
inline constexpr int kColliderVertices = 4;
inline constexpr int kColliderTriangles = 2;
inline void add_collider(Checkpoint& c) {
  const Eigen::Index n = c.positions.rows(), m = c.triangles.rows();
  Positions square(kColliderVertices, 3);
  square << 0, 0, -1, 1, 0, -1, 1, 1, -1, 0, 1, -1;
  const auto append = [&](Positions& points) {
    points.conservativeResize(n + kColliderVertices, 3);
    points.bottomRows(kColliderVertices) = square;
  };
  append(c.positions);
  append(c.rest_positions);
  append(c.finest_positions);
  append(c.solver.previous_positions);
  c.triangles.conservativeResize(m + kColliderTriangles, 3);
  c.triangles.bottomRows(kColliderTriangles) << n, n + 1, n + 2, n, n + 2, n + 3;
}

/// The part ranges of a fixture checkpoint: the plate, then the collider if it has one.
inline std::vector<PartRange> fixture_parts(const Checkpoint& c, bool collider) {
  const int n = static_cast<int>(c.positions.rows()) - (collider ? kColliderVertices : 0);
  const int m = static_cast<int>(c.triangles.rows()) - (collider ? kColliderTriangles : 0);
  std::vector<PartRange> parts{{"plate", PartKind::shell, 0, n, 0, m}};
  if (collider)
    parts.push_back({"floor", PartKind::collider, n, kColliderVertices, m, kColliderTriangles});
  return parts;
}

inline Checkpoint fixture_checkpoint(const FixtureJob& job, int l) {
  Checkpoint c;
  c.code_version = "0.1.0-test";
  c.parameters = job.parameters().dump();
  c.level = l;
  c.frame = 4;
  c.time = 0.4;
  fill_grid(l, job.depth(), job.bend, job.levels[l].lift, c);
  c.solver.progress = LevelProgress::level_done;
  c.solver.previous_positions = c.positions;
  if (job.elastic_energy && l + 1 == job.depth())
    c.solver.scalars["elastic_energy"] = *job.elastic_energy;
  // Frame f's Newton solve is the f-th falling run of the history (newton_history starts
  // each frame high again); its iterations count from 0.
  int frame = 1, iteration = 0;
  double last = INFINITY;
  for (double r : job.levels[l].residuals) {
    if (!std::isfinite(r)) continue;
    if (r > last) ++frame, iteration = 0;
    c.statistics.iterations.push_back({frame, iteration++, 1.0, r, r, 1.0, 0.01});
    last = r;
  }
  c.statistics.timings = job.levels[l].timings;
  if (job.collider) add_collider(c);
  return c;
}

/// The checkpoint's plate and collider as the executor writes them: `level_<l>.parts.h5` beside
/// the checkpoint.
inline void write_fixture_parts(const Checkpoint& c, const FixtureJob& job,
                                const std::filesystem::path& checkpoint_file) {
  TriMesh rest;
  rest.vertices = c.rest_positions;
  rest.triangles = c.triangles;
  PartMeshes meshes{c.level, c.frame, c.time,
                    split_into_parts(c.positions, rest, fixture_parts(c, job.collider))};
  write_part_meshes(
      checkpoint_file.parent_path() / fmt::format("level_{}.parts.h5", c.level), meshes);
}

/// A store `<dir>/.psq/psq.db` with the sweep "plates" of fixture_jobs() run as described,
/// checkpoints in `<dir>/.psq/runs/<id>/level_<l>.h5`. Returns the store's path.
inline std::filesystem::path make_report_fixture(const std::filesystem::path& dir) {
  const std::filesystem::path workspace = dir / ".psq";
  const std::filesystem::path database = workspace / "psq.db";
  db::JobStore store(database);
  const std::vector<FixtureJob> jobs = fixture_jobs();
  std::vector<db::NewJob> new_jobs;
  for (const FixtureJob& job : jobs)
    new_jobs.push_back(
        {job.id, job.parameters(), "plates.toml", job.depth(), db::method_of_depth(job.depth()), 1});
  store.add_sweep("plates", "sweeps/plates.toml", new_jobs);
  for (const FixtureJob& job : jobs) {
    if (job.state == db::JobState::queued) continue;
    const auto claim = store.claim_next({"fixture", "host", "0.1.0-test"}, 600);
    if (!claim || claim->job.id != job.id) throw std::logic_error("fixture: unexpected claim");
    for (int l = 0; l < job.depth(); ++l) {
      const FixtureLevel& level = job.levels[l];
      const std::string relative = fmt::format("runs/{}/level_{}.h5", job.id, l);
      const std::filesystem::path file = workspace / relative;
      db::LevelRecord record;
      record.level = l;
      record.status = level.status;
      record.iterations = static_cast<std::int64_t>(level.residuals.size());
      record.residuals = level.residuals;
      record.timings = level.timings;
      record.static_residuals = {{1, fixture_static_residual(l)}};
      record.frames = level.frames;
      record.error = level.error;
      if (level.status == db::LevelStatus::done) {
        std::uint64_t checksum = 0x1234;
        if (level.checkpoint != CheckpointCase::missing) {
          std::filesystem::create_directories(file.parent_path());
          const Checkpoint checkpoint = fixture_checkpoint(job, l);
          checksum = write_checkpoint(file, checkpoint);
          if (job.collider) write_fixture_parts(checkpoint, job, file);
        }
        const bool relative_path = level.checkpoint == CheckpointCase::workspace_relative ||
                                   level.checkpoint == CheckpointCase::corrupted;
        record.checkpoint_path = relative_path ? relative : file.string();
        record.checkpoint_checksum = checksum_text(checksum);  // as the executor records it
        if (level.checkpoint == CheckpointCase::corrupted) {
          std::fstream bytes(file, std::ios::in | std::ios::out | std::ios::binary);
          bytes.seekp(static_cast<std::streamoff>(std::filesystem::file_size(file) / 2));
          bytes.put('\x5a').put('\xa5');
        }
      }
      store.record_level(claim->lease, record);
    }
    store.finish(
        claim->lease,
        job.state == db::JobState::done ? db::Outcome::done : db::Outcome::failed_permanently,
        job.error);
  }
  return database;
}

}  // namespace psq::test
