#pragma once
// The solves of one quasistatic step of a system at one resolution, with the contact, friction
// and strain-limit terms its scene asks for (docs/contact.md,
// docs/friction-and-strain-limiting.md). QuasistaticSimulation steps a scene's frames with it;
// each level of a progressive solve steps its own meshes with it, over the level's proxy
// elastics.
//
// A frame's step starts from the last answer moved on by the last frame's motion, as far as
// that is safe (predict), then begins (begin_frame) by moving the scripted vertices to their
// targets: with contact, κ is chosen first (IPC), then they move directly when the CCD finds
// that move safe; otherwise they are freed and pulled toward the targets by a penalty of
// growing stiffness (KinematicPull) while the CCD line search keeps every iterate
// intersection-free, and they are pinned at the targets as soon as the rest of the way is safe.
// The step's solve (solve_held) follows with them fixed: Newton in chunks with κ and κ_s adapted
// between chunks, inside IPC's outer friction loop when the scene has friction. With strain
// limits, the line search starts from the barrier's feasible step, so no accepted iterate
// stretches a triangle to its limit.

#include <limits>
#include <map>
#include <memory>
#include <string>

#include "engine/sim/contact_term.hpp"
#include "engine/sim/friction_term.hpp"
#include "engine/sim/incremental_potential.hpp"
#include "engine/sim/kinematic_pull.hpp"
#include "engine/sim/probes.hpp"
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
  /// Whether Newton started from the last answer moved on by the last frame's motion
  /// (FrameSolver::predict) rather than from the last answer.
  bool predicted = false;
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
  /// The scale of the loads at the frame's time (scene.hpp, LoadScale).
  double load_scale = 1;
  /// The system's probes at the frame's answer (none below the finest level).
  std::vector<ProbeReading> probes;
};

/// Adds a solve to a frame's Newton record: iterations, history and times accumulate; the
/// verdict and the final values are the last solve's.
void append_solve(NewtonResult& frame, NewtonResult solve);

/// `progress` with its records numbered through the whole frame, from `taken` iterations on
/// (those before a restore): a frame takes several Newton solves (pull rounds, κ chunks,
/// friction iterations, settling steps), and a snapshot's iteration count must cover them all.
/// Empty when `progress` is.
NewtonSolver::Progress numbered_through_frame(NewtonSolver::Progress progress, int& taken);

class FrameSolver {
 public:
  /// `system` and `potential` (its incremental potential, with the system's own or another
  /// elastic model) are referenced; the solver adds its terms to the potential.
  /// @throws InputError when the rest state is not strictly below a shell's strain limit.
  FrameSolver(const ShellSystem& system, IncrementalPotential& potential);
  FrameSolver(const FrameSolver&) = delete;
  FrameSolver& operator=(const FrameSolver&) = delete;

  /// The contact term, or null when the scene has no contact.
  [[nodiscard]] ContactTerm* contact() { return contact_.get(); }
  /// The friction term, or null without contact or when every μ is 0.
  [[nodiscard]] const FrictionTerm* friction() const { return friction_.get(); }
  /// The strain-limit term, or null when no shell sets a strain limit.
  [[nodiscard]] StrainLimitTerm* strain_limit() { return strain_limit_.get(); }
  /// Whether stiffnesses adapt between Newton chunks (contact or strain limits).
  [[nodiscard]] bool adaptive() const { return contact_ || strain_limit_; }

  /// The start of a frame's step to record.time: without contact the pinned vertices move to
  /// their scripted positions (NumericalError when that makes the potential non-finite); with
  /// contact κ is initialized at x and the scripted vertices move directly or are pulled (the
  /// pull rounds are appended to record). Resets the contact statistics.
  void begin_frame(Eigen::VectorXd& x, FrameRecord& record, const NewtonSettings& settings,
                   const NewtonSolver::Progress& progress);
  /// Moves x's free DOFs on by `motion` (the last frame's motion), or by the largest fraction
  /// of it the CCD finds intersection-free, when the potential stays finite there; returns
  /// whether it moved. Newton's start only, the frame's objective is unchanged: a shell that
  /// keeps moving as it did (a cloth twisting on, a cloth falling) starts near its answer
  /// instead of a frame's motion behind it. Call before begin_frame, which then moves the
  /// scripted vertices from there.
  bool predict(Eigen::VectorXd& x, const Eigen::VectorXd& motion);
  /// One solve from x with the pinned vertices where they are, appended to record.newton. The
  /// caller has set the potential's xᵗ; friction is lagged at `previous` (xᵗ) and its slip
  /// measured from `frame_start`.
  void solve_held(Eigen::VectorXd& x, const Eigen::VectorXd& previous,
                  const Eigen::VectorXd& frame_start, FrameRecord& record,
                  const NewtonSettings& settings, const NewtonSolver::Progress& progress);
  /// The frame's load scale and probe readings at x; with contact its contact statistics, κ and
  /// the scripted vertices' distance from their targets.
  void finish_frame(const Eigen::VectorXd& x, FrameRecord& record);

  /// Adds the adaptive stiffnesses (κ and its range, each limited shell's κ_s and slack).
  void save_state(std::map<std::string, double>& state) const;
  /// Takes back what save_state wrote; missing names keep their values.
  void load_state(const std::map<std::string, double>& state);
  /// @throws InputError naming `what` unless x is strictly below every strain limit.
  void require_feasible(const Eigen::VectorXd& x, const std::string& what) const;

 private:
  /// Moves every scripted vertex to its target at `time` if that motion (the others held) is
  /// intersection-free by the CCD and the energy stays finite; returns whether it moved.
  bool move_scripted_vertices_if_safe(Eigen::VectorXd& x, double time);
  /// Newton on x over `dofs`; with adaptive stiffnesses in chunks, updated between them.
  NewtonResult solve_in_chunks(Eigen::VectorXd& x, const DofMap& dofs,
                               const NewtonSettings& settings,
                               const NewtonSolver::Progress& progress);
  /// IPC's κ update and Codim-IPC's κ_s update at x, for the terms the scene has; true when
  /// either changed (the objective is then another one).
  bool update_stiffnesses(const Eigen::VectorXd& x, bool steps_cut_by_ccd);

  const ShellSystem& system_;
  IncrementalPotential& potential_;
  std::unique_ptr<ContactTerm> contact_;           ///< null when the scene has no contact
  std::unique_ptr<FrictionTerm> friction_;         ///< null without contact or friction
  std::unique_ptr<StrainLimitTerm> strain_limit_;  ///< null when no shell sets a strain limit
  KinematicPull pull_;
  DofMap dofs_;
  /// The least weight of a pulled vertex: the stiffest shell's membrane stiffness (N/m).
  double pull_weight_floor_;
  NewtonSolver newton_;
};

}  // namespace psq
