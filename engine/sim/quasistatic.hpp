#pragma once
// Quasistatic stepping of a scene at one resolution: each frame moves the pinned vertices to
// their scripted positions and minimizes the incremental potential with Newton (frame_solver.hpp:
// with contact no accepted state intersects, with strain limits none reaches a limit), then,
// unless the scene's frame_solution is fixed_step, settles the frame to a static equilibrium
// (settling.hpp).

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include "engine/sim/frame_solver.hpp"
#include "engine/sim/incremental_potential.hpp"
#include "engine/sim/settling.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/solver/newton.hpp"

namespace psq {

class QuasistaticSimulation {
 public:
  /// Called for every Newton iteration of a frame (frame number, record).
  using Progress = std::function<void(int frame, const NewtonIteration&)>;

  /// Builds the shell system of `scene` and starts at its rest state.
  /// @throws InputError when the rest state is not strictly below a shell's strain limit.
  explicit QuasistaticSimulation(const Scene& scene);
  /// The same on one hierarchy level of `scene` as a problem of its own: the shells' rest
  /// meshes with their pin groups and the colliders' meshes of that level (ShellSystem's level
  /// constructor), carrying `loads` (3n, at scale 1) in place of the scene's, which are
  /// selected on the finest mesh.
  QuasistaticSimulation(const Scene& scene, const std::vector<LevelShellMesh>& shells,
                        const std::vector<TriMesh>& colliders, const Eigen::VectorXd& loads);

  [[nodiscard]] const ShellSystem& system() const { return system_; }
  /// The state of the last solved frame; inside step() (e.g. in its progress callback), the
  /// current Newton iterate of the frame being solved.
  [[nodiscard]] const Eigen::VectorXd& positions() const { return x_; }
  /// xᵗ, the anchor of the incremental potential of the frame being (or last) solved.
  [[nodiscard]] const Eigen::VectorXd& previous() const { return previous_; }
  /// Frames solved so far.
  [[nodiscard]] int frame() const { return frame_; }
  [[nodiscard]] int frame_count() const { return system_.scene().time.frames; }
  [[nodiscard]] const NewtonSettings& newton_settings() const { return settings_; }
  /// The contact term, or null when the scene has no contact.
  [[nodiscard]] ContactTerm* contact() { return frame_solver_.contact(); }
  /// The friction term, or null without contact or when every μ is 0.
  [[nodiscard]] const FrictionTerm* friction() const { return frame_solver_.friction(); }
  /// The strain-limit term, or null when no shell sets a strain limit.
  [[nodiscard]] StrainLimitTerm* strain_limit() { return frame_solver_.strain_limit(); }

  /// Settles frames `frame`, `frame` + 1, … only; the frames before it take their one step
  /// (their path, not an equilibrium). The schedule of a progressive solve's finest level, for
  /// a direct solve whose answer is its last frame; 1 (every frame) unless set.
  void settle_from_frame(int frame) { first_settled_frame_ = frame; }
  /// Whether frame `frame`'s step is followed by settling steps: the scene's frames are
  /// equilibria (frame_solution) and it is not before settle_from_frame's frame.
  [[nodiscard]] bool frame_settles(int frame) const;

  /// Solves the next frame: its step, then (frame_settles) its settling steps. A
  /// frame that does not converge, or does not settle, within solver.max_iterations is returned
  /// with newton.converged = false; numerical failures throw NumericalError.
  FrameRecord step(const Progress& progress = {});

  /// The adaptive stiffnesses reached so far (contact κ and its range, each limited shell's κ_s
  /// and last slack) and, inside a settling step, its growth index, by name: with positions,
  /// what a stored state needs besides the frame. Empty for a scene without contact or strain
  /// limits between frames.
  [[nodiscard]] std::map<std::string, double> adaptive_state() const;

  /// Continues from a saved state, exactly as if the run had not stopped. With
  /// `iterations_in_frame` = 0, frame `frame` is solved and `positions` is its result (the next
  /// step() solves frame + 1 from it). Otherwise frame `frame` is in progress: `positions` is its
  /// Newton iterate after `iterations_in_frame` iterations, and the next step() continues that
  /// solve with xᵗ = `previous` and the iterations left of solver.max_iterations.
  /// `adaptive_state` is adaptive_state() of that moment (names it lacks keep their start
  /// values). Exact for scenes without contact or strain limits; with them, exact between
  /// frames, while a frame in progress starts its contact set-up (κ, pulls, friction loop) again.
  /// @throws std::invalid_argument when the sizes or the frame do not fit this simulation;
  /// InputError when `positions` is not strictly below a shell's strain limit.
  void restore(int frame, const Eigen::VectorXd& positions, const Eigen::VectorXd& previous,
               int iterations_in_frame = 0,
               const std::map<std::string, double>& adaptive_state = {});

 private:
  /// Settling steps at the frame's loading (settling.hpp) from growth index settle_growth_
  /// until the equilibrium test passes or record.newton has used settings.max_iterations. With
  /// `continue_restored`, the first step continues a restored one (xᵗ = previous_).
  /// `restored_iterations`: the frame's iterations before the restore, not in record.
  void settle(FrameRecord& record, const NewtonSettings& settings,
              const NewtonSolver::Progress& progress, bool continue_restored,
              int restored_iterations);
  /// The Newton settings of the scene's solver at the system's scale.
  void configure_newton();

  ShellSystem system_;
  IncrementalPotential potential_;
  FrameSolver frame_solver_;
  NewtonSettings settings_;
  Eigen::VectorXd x_;
  Eigen::VectorXd previous_;
  /// The state the frame started from: friction's slip is measured from it through the frame's
  /// step and its settling steps, so that static friction holds a settled state instead of
  /// letting it creep by up to the slip threshold per settling step. After a restore inside a
  /// frame, the restored xᵗ.
  Eigen::VectorXd frame_start_;
  int frame_ = 0;
  int first_settled_frame_ = 1;  ///< settle_from_frame
  /// Newton iterations already spent on frame_ + 1 before a restore (0: start it afresh).
  int resumed_iterations_ = 0;
  /// Growth index of the settling step being solved; 0 outside settling (the frame's step).
  int settle_growth_ = 0;
  /// The frame's iterations (those before a restore included) when the settling step being
  /// solved started.
  int settle_step_start_ = 0;
};

}  // namespace psq
