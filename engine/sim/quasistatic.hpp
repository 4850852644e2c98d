#pragma once
// Quasistatic stepping of a scene at one resolution: each frame moves the pinned vertices to
// their scripted positions and minimizes the incremental potential with Newton.
//
// With contact (docs/contact.md), no accepted state may intersect, even while colliders and
// pinned sets move: at a frame's start κ is chosen (IPC), then the scripted vertices move to
// their targets directly when the CCD finds that move safe; otherwise they are freed and pulled
// toward the targets by a penalty of growing stiffness (KinematicPull) while the CCD line search
// keeps every iterate intersection-free, and they are pinned at the targets as soon as the rest
// of the way is safe. The frame's solve follows with them fixed.
//
// With strain limits (docs/friction-and-strain-limiting.md), no accepted iterate stretches a
// limited shell's triangle to its limit: the line search starts from the barrier's feasible
// step, and κ_s adapts between Newton chunks as κ does with contact.

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include "engine/sim/contact_term.hpp"
#include "engine/sim/friction_term.hpp"
#include "engine/sim/incremental_potential.hpp"
#include "engine/sim/kinematic_pull.hpp"
#include "engine/sim/settling.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/sim/strain_limit_term.hpp"
#include "engine/solver/newton.hpp"

namespace psq {

/// One solved frame.
struct FrameRecord {
  int frame = 0;      ///< 1-based; frame 0 is the rest state
  double time = 0.0;  ///< frame · Δt
  double elastic_energy = 0.0;
  /// Every Newton solve of the frame (pull rounds, the solve, re-solves after κ updates, the
  /// settling steps). With frame_solution = equilibrium, converged means that the frame's step
  /// converged and its settling reached the equilibrium within the iteration budget.
  NewtonResult newton;
  /// Settling steps after the frame's step (0 with frame_solution = fixed_step).
  int settle_steps = 0;
  /// ‖d‖∞/Δt of the Newton step of the last settling step (Δt·4⁶, a nearly inertia-free step) at
  /// the frame's answer: its distance to the static equilibrium, in the tolerance's measure. NaN
  /// when the frame was not settled (fixed_step, or its step or settling did not converge).
  double static_residual = std::numeric_limits<double>::quiet_NaN();
  // Contact scenes only (zero otherwise):
  ContactStats contact;          ///< barrier and CCD work, with the skips
  double barrier_stiffness = 0;  ///< κ at the end of the frame
  /// Penalty solves that pulled scripted vertices toward targets a direct move could not reach
  /// safely (0: moved directly).
  int kinematic_rounds = 0;
  /// Largest |coordinate| of a scripted vertex's distance from its target at the end [m]: 0
  /// unless the targets could not be reached without intersecting.
  double kinematic_offset = 0;
  /// Solves of IPC's outer friction loop (friction scenes only; 0 otherwise): friction lagged at
  /// the frame start, then re-lagged at each solution until the solution settles.
  int friction_iterations = 0;
  double friction_seconds = 0;  ///< lagging and evaluating friction (within assembly, line search)
};

/// Every frame's answer is a static equilibrium (settling.hpp) unless the scene's
/// frame_solution is fixed_step.

/// One quasistatic step without adaptive terms (no contact, no strain limit), as the levels of a
/// progressive solve take it; QuasistaticSimulation takes the same step for such scenes (its
/// chunked solve is then one Newton call), so a one-level progressive solve matches it: moves
/// the pinned vertices of x to their scripted positions at frame·Δt, checks that `objective` is
/// finite there, and minimizes it with Newton from x over the free DOFs of `dofs`, leaving the
/// result in x. The caller sets the objective's xᵗ first.
/// @throws NumericalError when moving the pins makes the objective non-finite, or from Newton.
NewtonResult solve_pinned_step(NewtonSolver& newton, Objective& objective,
                               const ShellSystem& system, const DofMap& dofs,
                               const NewtonSettings& settings, int frame, Eigen::VectorXd& x,
                               const NewtonSolver::Progress& progress);

class QuasistaticSimulation {
 public:
  /// Called for every Newton iteration of a frame (frame number, record).
  using Progress = std::function<void(int frame, const NewtonIteration&)>;

  /// Builds the shell system of `scene` and starts at its rest state.
  /// @throws InputError when the rest state is not strictly below a shell's strain limit.
  explicit QuasistaticSimulation(const Scene& scene);

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
  [[nodiscard]] ContactTerm* contact() { return contact_.get(); }
  /// The friction term, or null without contact or when every μ is 0.
  [[nodiscard]] const FrictionTerm* friction() const { return friction_.get(); }
  /// The strain-limit term, or null when no shell sets a strain limit.
  [[nodiscard]] StrainLimitTerm* strain_limit() { return strain_limit_.get(); }

  /// Solves the next frame: its step, then (frame_solution = equilibrium) its settling steps. A
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
  /// κ at the frame's start, then the scripted vertices to their targets (directly or pulled).
  void begin_contact_frame(FrameRecord& record, const NewtonSettings& settings,
                           const NewtonSolver::Progress& progress);
  /// Moves every scripted vertex to its target at `time` if that motion (the others held) is
  /// intersection-free by the CCD and the energy stays finite; returns whether it moved.
  bool move_scripted_vertices_if_safe(double time);
  /// Newton on x_ over `dofs`; with adaptive stiffnesses (contact κ, strain-limit κ_s) in
  /// chunks, with update_stiffnesses between them.
  NewtonResult solve_in_chunks(const DofMap& dofs, const NewtonSettings& settings,
                               const NewtonSolver::Progress& progress);
  /// IPC's κ update and Codim-IPC's κ_s update at x_, for the terms the scene has.
  void update_stiffnesses();
  /// The frame's solve with the scripted vertices fixed: solve_in_chunks, inside IPC's outer
  /// friction loop when the scene has friction.
  void solve_contact_frame(FrameRecord& record, const NewtonSettings& settings,
                           const NewtonSolver::Progress& progress);
  /// The frame's contact statistics.
  void finish_contact_frame(FrameRecord& record);
  /// One solve of the frame with its pinned vertices where they are (with contact: the friction
  /// loop and κ updates), appended to record.newton.
  void solve_held_frame(FrameRecord& record, const NewtonSettings& settings,
                        const NewtonSolver::Progress& progress);
  /// Settling steps at the frame's loading (settling.hpp) from growth index settle_growth_
  /// until the equilibrium test passes or record.newton has used settings.max_iterations. With
  /// `continue_restored`, the first step continues a restored one (xᵗ = previous_).
  /// `restored_iterations`: the frame's iterations before the restore, not in record.
  void settle(FrameRecord& record, const NewtonSettings& settings,
              const NewtonSolver::Progress& progress, bool continue_restored,
              int restored_iterations);

  ShellSystem system_;
  IncrementalPotential potential_;
  std::unique_ptr<ContactTerm> contact_;           ///< null when the scene has no contact
  std::unique_ptr<FrictionTerm> friction_;         ///< null without contact or friction
  std::unique_ptr<StrainLimitTerm> strain_limit_;  ///< null when no shell sets a strain limit
  KinematicPull pull_;
  DofMap dofs_;
  NewtonSolver newton_;
  NewtonSettings settings_;
  Eigen::VectorXd x_;
  Eigen::VectorXd previous_;
  /// The state the frame started from: friction's slip is measured from it through the frame's
  /// step and its settling steps, so that static friction holds a settled state instead of
  /// letting it creep by up to the slip threshold per settling step. After a restore inside a
  /// frame, the restored xᵗ.
  Eigen::VectorXd frame_start_;
  int frame_ = 0;
  /// Newton iterations already spent on frame_ + 1 before a restore (0: start it afresh).
  int resumed_iterations_ = 0;
  /// Growth index of the settling step being solved; 0 outside settling (the frame's step).
  int settle_growth_ = 0;
  /// The frame's iterations (those before a restore included) when the settling step being
  /// solved started.
  int settle_step_start_ = 0;
};

}  // namespace psq
