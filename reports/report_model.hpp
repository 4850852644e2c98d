#pragma once
// What a sweep report shows, gathered from the job store and the jobs' checkpoints before any
// file is written: per job its parameters, state and outputs, per level its convergence,
// time, error to the finest level and final shape. Every writer (CSV, JSON, Markdown, HTML)
// reads only this model. docs/reports.md defines each quantity.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "db/job_records.hpp"
#include "engine/io/checkpoint.hpp"
#include "engine/io/part_meshes.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq::db {
class JobStore;
}

namespace psq::reports {

/// A level's final shape: its shells and colliders with their rest positions (for the
/// displacement colours), from the level's part-meshes file beside its checkpoint, else the
/// checkpoint's whole mesh as one shell.
struct LevelShape {
  std::vector<PartMesh> parts;
};

/// One Newton solve of a level: a frame's step, or one settling step at a frame.
struct NewtonSolve {
  int frame = 0;
  std::vector<double> residuals;  ///< ‖∇E‖ at each iteration, from the level's checkpoint
};

/// One hierarchy level of a job.
struct LevelReport {
  int level = 0;  ///< 0 = coarsest
  /// The store's level status ("running", "done", "failed"); without a record of the level,
  /// "not refined" for a level past a previewed job's preview, else "missing".
  std::string status;
  std::int64_t iterations = 0;
  std::vector<double> residuals;  ///< per Newton iteration, as recorded in the store
  std::map<std::string, double> timings;
  std::optional<double> seconds;         ///< level_seconds(timings), if any timing
  std::optional<double> final_residual;  ///< the last finite residual
  /// (frame, static residual) of the level's frames settled to a static equilibrium, as stored.
  std::vector<std::pair<int, double>> static_residuals;
  /// The static residual of the level's last settled frame, when finite.
  std::optional<double> static_residual;
  /// max_i ‖P(x_l)_i − x_L,i‖ / diag(x_L): this level's state prolonged to the finest mesh
  /// against the finest level's converged state, relative to the latter's bounding box.
  std::optional<double> error_to_finest;
  /// The same measure against the reference of the job's design point (the finished
  /// direct_final job of the same scene and overrides, see design_point), instead of this job's
  /// own finest level: the error the benchmark plot and table show. Empty without a reference.
  std::optional<double> error_to_reference;
  /// What the refinement into this level did, by name, as stored (engine/progressive/
  /// refinement_statistics.hpp); empty at level 0 and for a direct solve.
  std::map<std::string, double> refinement;
  /// What the level computed, as stored (db::kLevelOutputs); empty unless done.
  std::map<std::string, double> outputs;
  /// The level's frames with their load scale and probe readings, as stored, in frame order.
  std::vector<db::FrameReadings> frames;
  /// The level's Newton solves in order, from its checkpoint (levels with a shape only).
  std::vector<NewtonSolve> solves;
  std::string checkpoint;           ///< as recorded in the store; empty if none
  std::string error;                ///< the level's failure message, if it failed
  /// Only for the levels of finished jobs, and the preview levels of previewed ones, with a
  /// readable checkpoint.
  std::optional<LevelShape> shape;
};

/// Scalar results of a finished job, from its finest level's checkpoint.
struct JobOutputs {
  std::optional<double> max_displacement;  ///< max_i ‖x_i − X_i‖ (m), finest level
  std::optional<double> elastic_energy;    ///< solver scalar "elastic_energy" (J), if recorded
  std::optional<double> total_seconds;     ///< sum of the levels' seconds
};

/// How a job computed its answer, for legends and tables: "direct", "direct, settled from the
/// refine frame", "progressive, N levels" or "coarse of N levels, prolonged".
std::string method_label(const db::Job& job);

/// What makes jobs the same design point whatever their method and depth: their scene and
/// overrides. Jobs of one design point solve the same problem on the same finest mesh, so their
/// positions can be compared vertex by vertex.
std::string design_point(const db::Job& job);

/// One job of the sweep.
struct JobReport {
  int number = 0;  ///< 1-based position in the sweep: the label used in plots and tables
  db::Job job;
  std::map<std::string, nlohmann::json> parameters;  ///< flatten_parameters(job.parameters)
  std::vector<LevelReport> levels;                   ///< one per level of the job's depth
  JobOutputs outputs;
  /// Checkpoints that are missing, damaged or inconsistent, and similar findings; shown in
  /// the report instead of aborting it.
  std::vector<std::string> problems;

  bool finished() const { return job.state == db::JobState::done; }
  /// The wall time of its levels 0..`level`, when each of them has timings.
  std::optional<double> seconds_through(std::size_t level) const;
  bool previewed() const { return job.state == db::JobState::previewed; }
};

/// A level's Newton iterations (as its checkpoint records them) cut into solves: a solve starts
/// where the frame changes or the iteration count within the frame does not advance (a solve's
/// last record takes no step, and the frame's next solve, a settling step, starts from the same
/// count).
std::vector<NewtonSolve> newton_solves(const std::vector<IterationRecord>& iterations);

/// What the shared hierarchy cache did for a sweep's jobs (db::HierarchyCacheUse, every
/// attempt): hits and builds, their seconds, and the build time the hits saved.
struct HierarchyCacheSummary {
  std::int64_t hits = 0;
  std::int64_t builds = 0;
  double hit_seconds = 0;    ///< reading the hits' files
  double build_seconds = 0;  ///< building and storing
  /// Σ over hits of (the mean seconds of the sweep's builds of the hit's key − the hit's own).
  double saved_seconds = 0;
  /// Hits of keys no job of the sweep built (an earlier sweep did): their saving is unknown.
  std::int64_t hits_without_build = 0;
};

/// The summary of these cache uses (see HierarchyCacheSummary).
HierarchyCacheSummary summarize_cache_uses(const std::vector<db::HierarchyCacheUse>& uses);

/// Everything a report of one sweep shows.
struct SweepReport {
  std::string name;
  std::string source;  ///< the sweep file
  std::filesystem::path database;
  std::map<db::JobState, std::int64_t> counts;
  /// The sweep's coarse-first rule (RefineKind::all for an ordinary sweep).
  db::RefineRule refine;
  std::vector<JobReport> jobs;
  /// Flattened parameter names whose value differs between jobs, sorted.
  std::vector<std::string> swept_parameters;
  /// Every flattened parameter name of any job, sorted: the table columns.
  std::vector<std::string> parameter_names;
  int max_depth = 0;  ///< the largest job depth: the number of per-level columns
  HierarchyCacheSummary hierarchy_cache;
};

/// Reads the sweep `sweep` from `store` and every checkpoint its finished jobs recorded, and
/// measures every level of a finished job against its design point's reference (the
/// finished direct_final job there, if any: LevelReport::error_to_reference).
/// Relative checkpoint paths are resolved against the store's directory (the workspace),
/// then against the current directory. A missing, damaged or inconsistent checkpoint becomes
/// a problem of its job. Throws InputError for an unknown sweep.
SweepReport gather_sweep_report(db::JobStore& store, const std::string& sweep);

}  // namespace psq::reports
