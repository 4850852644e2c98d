#pragma once
// The step-wise solver a job executor drives: a hierarchy of levels (0 = coarsest), each solved
// frame by frame, checkpointable between Newton iterations. A direct solve is a hierarchy of
// one level (jobs/direct_level_solver.hpp); the progressive solver has the same shape.

#include <Eigen/Core>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "db/job_records.hpp"
#include "engine/io/part_meshes.hpp"
#include "engine/mesh/tri_mesh.hpp"
#include "engine/solver/solver_stats.hpp"

namespace psq::jobs {

/// One solved frame of a level.
struct LevelFrame {
  int level = 0;
  int frame = 0;           ///< 1-based; frame 0 is the rest state
  bool converged = false;  ///< met the level's tolerance
  /// Stopped unconverged at round-off: the tolerance is finer than double precision resolves.
  bool stagnated = false;
  /// Whether the frame had to converge; a preview level's frame may stop at its budget.
  bool must_converge = true;
  int iterations = 0;           ///< Newton iterations of the frame, including any before a restore
  double step_norm = 0.0;       ///< final ‖d‖∞ / Δt
  double gradient_norm = 0.0;   ///< final ‖∇E‖
  double elastic_energy = 0.0;  ///< of the frame's result, at the finest scale (J)
  /// Why a frame that had to converge did not, when the solver knows better than "its Newton
  /// budget ran out" (a settling that stalled); empty otherwise.
  std::string failure;
  PhaseTimes times;             ///< of this step() call
  /// The frame's load scale and its probe readings (none below the finest level).
  db::FrameReadings readings;
};

class LevelSolver {
 public:
  /// Called after every Newton iteration with the frame being solved (1-based). When the record
  /// took a step (step_length > 0), positions() is the new iterate and previous() its xᵗ.
  using Progress = std::function<void(int frame, const NewtonIteration&)>;

  virtual ~LevelSolver() = default;

  [[nodiscard]] virtual int level_count() const = 0;
  /// The level being solved, 0 = coarsest.
  [[nodiscard]] virtual int level() const = 0;
  /// Frames of this level solved so far.
  [[nodiscard]] virtual int frame() const = 0;
  /// Frames this level solves in all (for progress estimates).
  [[nodiscard]] virtual int frame_count() const = 0;
  /// This level has solved all its frames: refine() or, at the finest level, finished.
  [[nodiscard]] virtual bool level_done() const = 0;
  /// The finest level is done.
  [[nodiscard]] virtual bool finished() const = 0;
  /// Solves the next frame of the current level. Throws NumericalError on a numerical failure.
  virtual LevelFrame step(const Progress& progress) = 0;
  /// Told each phase of a refinement as it starts (engine/progressive/safe_refinement.hpp).
  using RefinementPhase = std::function<void(const std::string& phase)>;
  /// Moves to the next finer level, initialized from the current one, telling `phase` each
  /// phase of the work. Requires level_done().
  virtual void refine(const RefinementPhase& phase) = 0;
  /// What the refinement into the current level did, by name (engine/progressive/
  /// refinement_statistics.hpp); empty at level 0, for a direct solve and after restore().
  [[nodiscard]] virtual std::map<std::string, double> refinement_statistics() const {
    return {};
  }
  /// How the solver obtained its hierarchies through the hierarchy cache when it was made (for
  /// the store); none for a direct solve or without a cache.
  [[nodiscard]] virtual std::vector<db::HierarchyCacheUse> hierarchy_cache_uses() const {
    return {};
  }
  /// The current level's positions (3n, flat); the current iterate during step().
  [[nodiscard]] virtual const Eigen::VectorXd& positions() const = 0;
  /// xᵗ of the frame being (or last) solved.
  [[nodiscard]] virtual const Eigen::VectorXd& previous() const = 0;
  /// The rest mesh of the current level.
  [[nodiscard]] virtual const TriMesh& level_rest_mesh() const = 0;
  /// The shells and colliders of the current level: where each lies in level_rest_mesh() and
  /// positions().
  [[nodiscard]] virtual std::vector<PartRange> level_parts() const = 0;
  /// The current level's state prolonged to the finest mesh (positions() at the finest level).
  [[nodiscard]] virtual Positions finest_positions() const = 0;
  /// The rest positions of the finest mesh, from which finest_positions() is displaced.
  [[nodiscard]] virtual const Positions& finest_rest_positions() const = 0;
  /// Whether frame `frame` of the current level ends with settling steps to a static equilibrium
  /// (engine/sim/settling.hpp): then the step norm of its last Newton record is its static
  /// residual.
  [[nodiscard]] virtual bool settles_frame(int frame) const = 0;
  /// Further state the solver needs to continue exactly, by name (stored in checkpoints as
  /// solver scalars and handed back to restore()); none by default.
  [[nodiscard]] virtual std::map<std::string, double> state() const { return {}; }
  /// Continues from a checkpoint of level `level`. With `iterations_in_frame` = 0, frame
  /// `frame` is solved and `positions` is its result; otherwise frame `frame` is in progress
  /// after that many Newton iterations from xᵗ = `previous`, and the next step() continues it
  /// so that the result equals an uninterrupted run's. `state` is what state() returned at
  /// that moment (or empty for a checkpoint without it).
  virtual void restore(int level, int frame, const Eigen::VectorXd& positions,
                       const Eigen::VectorXd& previous, int iterations_in_frame,
                       const std::map<std::string, double>& state) = 0;
};

}  // namespace psq::jobs
