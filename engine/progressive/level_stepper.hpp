#pragma once
// Quasistatic stepping at one level: each step moves the pinned vertices to their scripted
// positions and minimizes the level's objective with Newton, starting from the previous step,
// with the contact, friction and strain-limit terms of the scene on the level's own meshes
// (FrameSolver: intersection-free and strictly within the strain limits at every accepted
// iterate).

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "engine/progressive/level_objective.hpp"
#include "engine/sim/frame_solver.hpp"
#include "engine/sim/settling.hpp"
#include "engine/solver/newton.hpp"

namespace psq {

class LevelStepper {
 public:
  /// `system` is referenced (it must outlive the stepper); its pinned vertices are the fixed
  /// DOFs. `settings.step_scale` should be the scene's Δt.
  /// @throws InputError when the rest state is not strictly below a shell's strain limit.
  LevelStepper(const ShellSystem& system, std::unique_ptr<LevelObjective> objective,
               const NewtonSettings& settings);

  [[nodiscard]] const ShellSystem& system() const { return system_; }
  [[nodiscard]] const NewtonSettings& settings() const { return settings_; }
  [[nodiscard]] FrameSolver& frame_solver() { return frame_solver_; }

  /// One step to `frame` (time frame·Δt) from x, which becomes xᵗ; x is overwritten with the
  /// result. A step that does not converge within settings().max_iterations is returned with
  /// newton.converged = false.
  /// @throws NumericalError when moving the pins makes the objective non-finite, or from Newton.
  FrameRecord step(Eigen::VectorXd& x, int frame, const NewtonSolver::Progress& progress = {});
  /// The same as a settling step: the inertia-like term uses `time_step` instead of Δt.
  FrameRecord step(Eigen::VectorXd& x, int frame, double time_step,
                   const NewtonSolver::Progress& progress = {});
  /// A step from xᵗ = `previous` that already took `iterations_done` Newton iterations of the
  /// budget `settings` gives (the level's settings() or another budget and tolerance for this
  /// step) and reached the iterate x: Newton continues from x with the iterations left, numbering them
  /// (and counting them in the record) after those done, so that a step resumed from a stored
  /// iterate ends exactly where the uninterrupted one does (with contact: exactly between
  /// steps; inside one, κ and the scripted moves start again). x is overwritten with the result.
  /// Friction's slip is measured from `frame_start` (the frame's first xᵗ; empty: `previous`).
  FrameRecord step(const Eigen::VectorXd& previous, Eigen::VectorXd& x, int frame, double time_step,
                   int iterations_done, const NewtonSettings& settings,
                   const NewtonSolver::Progress& progress = {},
                   const Eigen::VectorXd& frame_start = {});

 private:
  const ShellSystem& system_;
  std::unique_ptr<LevelObjective> objective_;
  FrameSolver frame_solver_;
  NewtonSettings settings_;
};

}  // namespace psq
