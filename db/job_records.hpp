#pragma once
// The values the job store takes and returns: jobs, leases, per-level records, sweep counts.
// Plain data; the rules that move a job between states live in JobStore.

#include <array>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "db/refine_rule.hpp"

namespace psq::db {

/// Where a job is in its life. queued → running → done; running → queued (released, or a
/// failed attempt with attempts left, or a lease that expired); running → failed (no attempts
/// left, or a permanent failure); queued/running → cancelled; failed/cancelled → queued (retry).
/// A job of a coarse-first sweep stops at its preview levels: running → previewed; promoted,
/// previewed → queued, and it then runs its finer levels.
enum class JobState { queued, running, done, failed, cancelled, previewed };
inline constexpr std::array kAllJobStates{JobState::queued,    JobState::running,
                                          JobState::done,      JobState::failed,
                                          JobState::cancelled, JobState::previewed};
std::string_view to_string(JobState state);
/// Throws std::invalid_argument for a name that is not a state.
JobState job_state_from_string(std::string_view name);

/// Status of one hierarchy level of a job: running (an in-level snapshot), done, failed.
enum class LevelStatus { running, done, failed };
std::string_view to_string(LevelStatus status);
/// Throws std::invalid_argument for a name that is not a level status.
LevelStatus level_status_from_string(std::string_view name);

/// How an attempt ended. `failed` is retried while attempts remain; `failed_permanently`
/// (input the user must fix: retrying cannot help) ends the job at once; `previewed`: the job
/// ran the levels it was to run before promotion (Job::levels_to_run).
enum class Outcome { done, failed, failed_permanently, previewed };

/// How a job computes its answer (docs/sweep-format.md, "Methods"): `direct` solves the finest
/// mesh alone, every frame settled to an equilibrium; `direct_final` solves it with the schedule
/// of a progressive solve's finest level (frames before the refine frame one step each, the
/// refine frame and those after it settled), the direct baseline of a final-frame answer;
/// `progressive` solves a hierarchy from its coarsest level to the finest; `coarse_prolonged`
/// solves the coarsest mesh of a hierarchy directly, with its own elastics, and prolongs that
/// answer to the finest mesh, the paper's coarse baseline.
enum class Method { direct, direct_final, progressive, coarse_prolonged };
inline constexpr std::array kAllMethods{Method::direct, Method::direct_final,
                                        Method::progressive, Method::coarse_prolonged};
/// Whether a job of `method` builds a hierarchy (and so has a depth of 2 or more).
bool uses_hierarchy(Method method);
std::string_view to_string(Method method);
/// Throws std::invalid_argument for a name that is not a method.
Method method_from_string(std::string_view name);
/// The method of a job that names none (every job before methods existed): direct at depth 1,
/// progressive above.
Method method_of_depth(int depth);

/// A job as a sweep submits it. `id` is the hash of the canonical parameters (computed by the
/// sweep expansion); the same id always means the same job.
struct NewJob {
  std::string id;
  nlohmann::json parameters;  ///< stored canonically: keys sorted, compact
  std::string scene;          ///< the scene file
  /// Levels the job solves and records: the hierarchy depth of a progressive job, 1 for a
  /// direct or coarse-prolonged one (whose hierarchy depth is in its parameters).
  int depth = 1;
  Method method = Method::direct;
  int max_attempts = 3;       ///< failed attempts allowed before the job stays failed
  /// Levels run before the job waits for promotion (a coarse-first sweep); empty: all.
  std::optional<int> preview_levels = std::nullopt;
};

/// Where and with what a job ran (its latest attempt).
struct Provenance {
  std::string code_version;
  std::string host;
  std::optional<double> started_at;  ///< when the latest attempt was claimed
  std::optional<double> ended_at;    ///< when the job last finished or failed
};

/// A job as stored. Times are seconds since the Unix epoch.
struct Job {
  std::string id;
  nlohmann::json parameters;
  std::string scene;
  int depth = 1;  ///< levels it solves and records (NewJob::depth)
  Method method = Method::direct;
  JobState state = JobState::queued;
  /// Claims so far: the fencing token of the latest claim. Never decreases, not even on retry,
  /// so a token handed out once is never valid again after a new claim.
  std::int64_t attempt = 0;
  /// Failed attempts since the last retry: explicit failures, and workers that died without
  /// progress since the job's last new checkpoint (docs/job-store.md).
  std::int64_t failures = 0;
  std::int64_t max_attempts = 1;
  std::string lease_owner;  ///< worker holding the lease; empty unless running
  std::optional<double> lease_expiry;
  std::optional<double> heartbeat_at;
  std::string error;  ///< the latest failure's message; empty if none (cleared when done)
  Provenance provenance;
  double created_at = 0;
  /// Levels of its preview, when a coarse-first sweep listed it; empty: it runs every level.
  std::optional<int> preview_levels;
  /// Promoted past its preview (by its sweep's rule or by hand).
  bool promoted = false;

  /// The levels this job runs before it stops: its preview, unless promoted, else all.
  int levels_to_run() const { return preview_levels && !promoted ? *preview_levels : depth; }
};

/// Who claims: a worker's id (unique among live workers, e.g. host:pid), its host and the
/// code version recorded as the job's provenance.
struct WorkerInfo {
  std::string id;
  std::string host;
  std::string code_version;
};

/// The right to write a job's results, valid while the job is running with this attempt.
struct Lease {
  std::string job_id;
  std::int64_t attempt = 0;
  double seconds = 0;  ///< how far each heartbeat pushes the expiry
};

/// A claimed job and the lease that must accompany every write about it.
struct Claim {
  Job job;
  Lease lease;
};

/// A probe's reading at one frame (engine/sim/probes.hpp): `kind` "displacement", the mean
/// displacement of a vertex selection [m], or "reaction", the force a pinned set carries [N].
struct ProbeValue {
  std::string probe;  ///< the probe's name in the scene
  std::string kind;
  std::array<double, 3> value{};
  bool operator==(const ProbeValue&) const = default;
};

/// One frame of a level: the scale of its loads and its probes' readings at its answer.
struct FrameReadings {
  int frame = 0;  ///< 1-based
  double load_scale = 1;
  std::vector<ProbeValue> probes;
  bool operator==(const FrameReadings&) const = default;
};

/// The record of one hierarchy level of a job.
struct LevelRecord {
  int level = 0;  ///< 0 = coarsest; depth − 1 = finest
  LevelStatus status = LevelStatus::running;
  std::int64_t iterations = 0;
  std::vector<double> residuals;         ///< per iteration (NaN allowed: stored as null)
  std::map<std::string, double> timings;  ///< seconds per named phase
  /// (frame, static residual ‖d‖∞/Δt) of each frame whose answer was settled to a static
  /// equilibrium (engine/sim/settling.hpp), in frame order (NaN allowed: stored as null).
  std::vector<std::pair<int, double>> static_residuals;
  /// What the refinement into this level did, by name (engine/progressive/
  /// refinement_statistics.hpp); empty at level 0 and for a direct solve.
  std::map<std::string, double> refinement;
  /// What the finished level computed, by name (db::kLevelOutputs); empty unless done.
  std::map<std::string, double> outputs;
  /// Frames with their load scale and probe readings. Written: the frames solved since the
  /// level's last record, each replacing a stored row of its frame (a frame solved again after
  /// a resume, or a settling step of a frame already recorded); read: every stored frame of
  /// the level, in frame order.
  std::vector<FrameReadings> frames;
  std::string checkpoint_path;            ///< empty if none
  std::string checkpoint_checksum;        ///< of the checkpoint file; empty if none
  std::string error;                      ///< empty unless failed
  std::int64_t attempt = 0;  ///< the attempt that wrote it (set by the store on write)
  double updated_at = 0;     ///< set by the store on write
};

/// How one attempt of a job obtained one mesh's decimation hierarchy through the shared
/// hierarchy cache (engine/hierarchy/hierarchy_cache.hpp): read from the cache (a hit), or built
/// and stored; and the seconds that took. A hit saves what a build of the same key costs.
struct HierarchyCacheUse {
  std::string key;  ///< the cache key, 16 hex digits
  bool hit = false;
  double seconds = 0;
  std::int64_t attempt = 0;  ///< the attempt that obtained it (set by the store on write)
};

/// What adding a sweep did (or, in a dry run, would do).
struct SweepAddition {
  std::vector<std::string> added;  ///< ids of the jobs that were new, in the sweep's order
  std::int64_t already_present = 0;
};

/// What a selection of previewed points did.
struct Promotion {
  std::int64_t candidates = 0;        ///< points with a preview the rule judged
  std::vector<std::string> selected;  ///< ids the rule selected, in job order
  std::vector<std::string> promoted;  ///< of those, the ones that were waiting at preview
};

/// Job counts of one sweep.
struct SweepStatus {
  std::string name;
  std::string source;
  double created_at = 0;
  std::map<JobState, std::int64_t> counts;  ///< every state present, zeros included
  std::int64_t expired_leases = 0;  ///< running jobs whose worker stopped heartbeating
  RefineRule refine;                ///< what follows the previews (RefineKind::all: none)
  std::int64_t total() const;
};

/// A job with its level records, coarsest first, and its attempts' hierarchy cache uses.
struct JobResult {
  Job job;
  std::vector<LevelRecord> levels;
  std::vector<HierarchyCacheUse> hierarchy_uses;  ///< in the order recorded
};

/// Which jobs an operation applies to.
class JobSelection {
 public:
  static JobSelection all() { return JobSelection(Kind::all, {}); }
  static JobSelection sweep(std::string name) { return JobSelection(Kind::sweep, std::move(name)); }
  static JobSelection job(std::string id) { return JobSelection(Kind::job, std::move(id)); }

  enum class Kind { all, sweep, job };
  Kind kind() const { return kind_; }
  /// The sweep name or job id (empty for all).
  const std::string& name() const { return name_; }

 private:
  JobSelection(Kind kind, std::string name) : kind_(kind), name_(std::move(name)) {}
  Kind kind_;
  std::string name_;
};

}  // namespace psq::db
