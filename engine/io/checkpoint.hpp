#pragma once
// Checkpoints: the complete state of one job level in one HDF5 file, enough for a solver to
// resume it, written atomically and verifiable on its own. Layout and rules:
// docs/checkpoint-format.md.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/error.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Version of the checkpoint layout written by this program. Raise it whenever the layout or the
/// content checksum changes; files of a newer version are refused.
inline constexpr int checkpoint_schema_version = 3;

/// A checkpoint that cannot be written, or read back and trusted: missing, truncated, damaged,
/// foreign or newer. The message names the file and what is wrong.
class CheckpointError : public InputError {
 public:
  using InputError::InputError;
};

/// A consistent checkpoint that the file system would not take (no space, read-only, no
/// permission, a missing directory): the environment's failure, not the checkpoint's.
class CheckpointWriteError : public CheckpointError {
 public:
  using CheckpointError::CheckpointError;
};

/// Where in a level's work a checkpoint was taken: what a resuming solver does next.
enum class LevelProgress {
  inside_frame,  ///< Newton is still iterating on `frame`: continue it from `positions`
  frame_done,    ///< `frame` converged: the next one starts with xᵗ = `positions`
  level_done,    ///< the level is finished: refine from it, or report it
};

/// One Newton iteration of the level (the residual history plotted in reports).
struct IterationRecord {
  int frame = 0;
  int iteration = 0;           ///< 0-based within the frame
  double energy = 0.0;         ///< E(x) at the start of the iteration
  double gradient_norm = 0.0;  ///< ‖∇E(x)‖₂ over the free DOFs
  double step_norm = 0.0;      ///< ‖d‖∞ / Δt
  double step_length = 0.0;    ///< accepted line-search α
  double seconds = 0.0;        ///< wall time of the iteration

  bool operator==(const IterationRecord&) const = default;
};

/// What the quasistatic stepper needs besides the positions to continue exactly where it was.
struct SolverState {
  LevelProgress progress = LevelProgress::frame_done;
  /// xᵗ: the positions at the end of the frame before `frame`, the anchor of the incremental
  /// potential 1/(2Δt²)‖x − xᵗ‖²_M. Same shape as the positions.
  Positions previous_positions;
  /// Newton iterations already taken in `frame` (counts against the iteration limit on resume).
  int iterations_in_frame = 0;
  /// Further named scalars of the solver state (e.g. the adaptive barrier stiffness κ).
  std::map<std::string, double> scalars;
};

/// The scalar holding the elastic energy of the level's last solved frame, at the finest scale
/// (J); the reports' energy output.
inline constexpr const char* kElasticEnergyScalar = "elastic_energy";

/// Statistics of the level so far.
struct LevelStatistics {
  std::vector<IterationRecord> iterations;  ///< every Newton iteration of the level, in order
  std::map<std::string, double> timings;    ///< seconds by phase (assembly, factorization, …)
  /// What the refinement into this level did, by name (engine/progressive/
  /// refinement_statistics.hpp); empty at level 0, for a direct solve, and in files of schema
  /// version 2.
  std::map<std::string, double> refinement;
};

/// The state of one job level at one moment.
struct Checkpoint {
  /// Layout version the checkpoint was read from; write_checkpoint always writes
  /// checkpoint_schema_version.
  int schema_version = checkpoint_schema_version;
  std::string code_version;  ///< version of the program that computed the state
  std::string parameters;    ///< the job's canonical parameters, JSON text
  int level = 0;             ///< hierarchy level, 0 = coarsest
  int frame = 0;             ///< frame of the loading script, 0 = rest state
  double time = 0.0;         ///< simulated time of `frame`, seconds
  Positions positions;       ///< n×3, current vertex positions (metres)
  Positions rest_positions;  ///< n×3, rest shape of this level
  Triangles triangles;       ///< m×3, vertex indices of each triangle, 0-based
  /// The state prolonged to the finest mesh of the hierarchy (equal to `positions` at the
  /// finest level): what reports compare between levels.
  Positions finest_positions;
  SolverState solver;
  LevelStatistics statistics;
};

/// Object names inside a checkpoint file, shared by its writer, its reader and the XDMF sidecar.
namespace checkpoint_layout {
inline constexpr std::string_view positions = "/mesh/positions";
inline constexpr std::string_view rest_positions = "/mesh/rest_positions";
inline constexpr std::string_view triangles = "/mesh/triangles";
inline constexpr std::string_view finest_positions = "/mesh/finest_positions";
}  // namespace checkpoint_layout

/// Writes `checkpoint` to `path` atomically: the file is written to a temporary name in the
/// same directory, read back and verified, flushed to disk (fsync) and renamed over `path`, so
/// `path` is always either the previous file or the complete new one. Stores a checksum of the
/// content (every attribute and dataset) inside the file. Returns the FNV-1a 64 checksum of the
/// bytes of the written file, for the store to record. Throws CheckpointError naming `path` if
/// the checkpoint is inconsistent (shapes, triangle indices, non-finite values, parameters that
/// are not JSON), and CheckpointWriteError if it cannot be written (the system's reason, e.g.
/// "No space left on device"); the previous file is then left as it was.
std::uint64_t write_checkpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);

/// Reads and verifies a checkpoint: the file's checksum against `expected_file_checksum` when
/// given, the format marker, the schema version (a newer one is refused), the content checksum,
/// shapes and indices. Throws CheckpointError naming the file and the problem for a missing,
/// empty, truncated, damaged, foreign or newer file.
Checkpoint read_checkpoint(const std::filesystem::path& path,
                           std::optional<std::uint64_t> expected_file_checksum = std::nullopt);

}  // namespace psq
