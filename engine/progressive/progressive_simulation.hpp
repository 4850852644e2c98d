#pragma once
// Progressive quasistatic simulation (paper §3, §4.4–4.5; DESIGN.md §6): previews at the coarsest
// level over the loading script, then refinement level by level at the refine frame, and the true
// objective at the finest level to convergence.
//
// Schedule, one quasistatic step per call of step():
//   level 0 (levels > 1): frames 1..refine_frame with the proxy objective, at most
//     preview_iterations Newton-type iterations per step; then "settling" steps at the refine
//     frame (loading held, xᵗ ← x each step) until a step changes the solution by
//     ‖x − xᵗ‖∞/Δt < preview_tolerance;
//   refine(): the target P^l_{l+1}(x_l) with the pinned vertices at their scripted positions;
//     without contact it is the initializer, with contact safe_initialize (safe_refinement.hpp)
//     expands x_l toward it without intersecting;
//   intermediate levels: settling steps at the refine frame as above;
//   finest level: settling steps with the true incremental potential, each solved to the
//     scene's tolerance, until the change is below that tolerance; then frames
//     refine_frame+1..frames, each one converged step and (the scene's frame_solution =
//     equilibrium) its settling steps.
// With levels = 1 the finest level steps frames 1..frames as QuasistaticSimulation does.
// With contact (and friction) every level steps its own meshes and the colliders with the
// level's barrier, CCD line search and κ adaptation (FrameSolver), so every state of every level
// is free of intersections. A step of a settling sequence moves no pins; its frame solver only
// raises κ to the balance at its start when that is higher.

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engine/hierarchy/hierarchy_cache.hpp"
#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/progressive/level_stepper.hpp"
#include "engine/progressive/proxy_objective.hpp"
#include "engine/progressive/safe_refinement.hpp"
#include "engine/progressive/strain_limit_correction.hpp"
#include "engine/progressive/system_prolongation.hpp"

namespace psq {

struct ProgressiveSettings {
  /// Levels, ratio, preview tolerance and iterations, refine frame (the scene's [hierarchy]).
  HierarchyOptions schedule;
  ProxyGradient gradient = ProxyGradient::exact;
  /// Where built hierarchies are cached; empty: build without a cache.
  std::filesystem::path cache_dir;
  /// Settling steps per level before the level is given up as not converged.
  int max_settle_steps = 200;

  /// The scene's [hierarchy] settings, the default gradient, no cache.
  static ProgressiveSettings from_scene(const Scene& scene);
};

/// One hierarchy per shell of `finest` (its meshes and pin groups), then one per collider
/// (paper §4.6: collision objects are decimated, prolonged and coloured like shells), built
/// with the schedule's levels and vertex ratio, through the cache in settings.cache_dir when
/// that is set. A collider that cannot be decimated as far has fewer levels. With a cache, each
/// hierarchy's cache use is appended to `uses` (when given), in the order built.
std::vector<MeshHierarchy> build_hierarchies(const ShellSystem& finest,
                                             const ProgressiveSettings& settings,
                                             std::vector<HierarchyCacheUse>* uses = nullptr);

/// A level below the finest as a problem of its own, for a direct solve of that level whose
/// answer is prolonged to the finest mesh (the paper's coarse baseline): its shells' rest meshes
/// with their pin groups, its colliders' meshes, the finest loads carried to it by Uᵀ (by virtual
/// work, so the level carries the same total force), P^l to the finest mesh, and the finest
/// rest positions, against which the prolonged answer's displacement is measured.
struct CoarseProblem {
  std::vector<LevelShellMesh> shells;
  std::vector<TriMesh> colliders;
  Eigen::VectorXd loads;
  SystemProlongation to_finest;
  Positions finest_rest;
};

/// One step of a progressive solve.
struct ProgressiveStep {
  int level = 0;
  /// A step at the refine frame with the loading held (frame.frame does not advance): a
  /// settling step, or in a fixed-step scene the refine frame's one step at a level entered by
  /// refinement.
  bool settling = false;
  /// A settling step that passed the equilibrium test (settling_done): its frame is settled.
  bool equilibrium = false;
  double change = 0.0;  ///< ‖x − xᵗ‖∞/Δt of this step
  /// Whether the step's verdict counts: a finest-level step, except a settling step on the way
  /// (which may stop at its budget; the one that ends the settling counts).
  bool judged = false;
  /// The verdict: Newton converged and, for a settling step, the equilibrium was reached.
  bool converged = false;
  /// On the step that ends a settling without an equilibrium: why it stopped and what to change
  /// (empty otherwise).
  std::string settling_failure;
  /// Frame, time, fine-scale elastic energy (Ψ_L(P^l(x))), Newton history and timings.
  FrameRecord frame;
};

class ProgressiveSimulation {
 public:
  /// Called for every Newton iteration (level, frame, record).
  using Progress = std::function<void(int level, int frame, const NewtonIteration&)>;

  /// Builds the finest system and, when settings.schedule.levels > 1, the hierarchies of its
  /// shells and colliders (build_hierarchies).
  /// @throws InputError for invalid settings (naming the setting).
  ProgressiveSimulation(const Scene& scene, const ProgressiveSettings& settings);
  /// The same with given hierarchies: one per shell (finest level = the shell's mesh), then
  /// either one per collider or none (the colliders keep their own mesh at every level). The
  /// shells' hierarchies set the level count; a shell or collider with fewer levels keeps its
  /// coarsest mesh at the lowest levels, one with more uses its finer levels only.
  ProgressiveSimulation(const Scene& scene, const ProgressiveSettings& settings,
                        std::vector<MeshHierarchy> hierarchies);
  ~ProgressiveSimulation();
  ProgressiveSimulation(const ProgressiveSimulation&) = delete;
  ProgressiveSimulation& operator=(const ProgressiveSimulation&) = delete;

  [[nodiscard]] int level_count() const { return level_count_; }
  [[nodiscard]] int level() const { return level_; }
  [[nodiscard]] int frame() const { return frame_; }
  [[nodiscard]] int frame_count() const { return finest_.scene().time.frames; }
  [[nodiscard]] int refine_frame() const { return refine_frame_; }
  [[nodiscard]] bool level_done() const;
  /// The frame reached needs no more settling steps (the next step, if any, is a new frame's).
  [[nodiscard]] bool frame_settled() const { return settled_; }
  [[nodiscard]] bool finished() const { return finest_level() && level_done(); }
  /// The current level is the finest: its steps must converge, while coarser levels are
  /// previews whose steps may stop at preview_iterations.
  [[nodiscard]] bool finest_level() const { return level_ + 1 == level_count_; }
  /// Whether the current level is done, every settling of its frames met its tolerance (rather
  /// than stopping at max_settle_steps or stalling) and, in a fixed-step scene, every judged
  /// step converged.
  [[nodiscard]] bool level_converged() const {
    return level_done() && !settling_failed_ && !unconverged_step_;
  }

  /// Tolerance on ‖d‖∞/Δt (and on the settling change) at the current level.
  [[nodiscard]] double tolerance() const;
  /// The finest level's tolerance: the scene's, or 1e-4 × bounding-box diagonal per second.
  [[nodiscard]] double finest_tolerance() const { return finest_tolerance_; }
  [[nodiscard]] const ShellSystem& finest_system() const { return finest_; }
  [[nodiscard]] const ShellSystem& level_system() const;
  [[nodiscard]] const TriMesh& level_rest_mesh() const { return level_system().rest_mesh(); }
  [[nodiscard]] const std::vector<MeshHierarchy>& hierarchies() const { return hierarchies_; }
  /// What the hierarchy cache did for each hierarchy this simulation built (empty without a
  /// cache, or when the hierarchies were given).
  [[nodiscard]] const std::vector<HierarchyCacheUse>& hierarchy_cache_uses() const {
    return cache_uses_;
  }
  /// What each refinement's safe initialization did (contact scenes; in refinement order).
  [[nodiscard]] const std::vector<RefinementStats>& refinements() const { return refinements_; }
  /// What each refinement's strain-limit correction did (scenes with a strain limit; in
  /// refinement order).
  [[nodiscard]] const std::vector<StrainCorrectionStats>& strain_corrections() const {
    return strain_corrections_;
  }

  /// Current positions of the current level (flat, 3n).
  [[nodiscard]] const Eigen::VectorXd& positions() const { return x_; }
  /// xᵗ: the positions the last step started from (equal to positions() before any step).
  [[nodiscard]] const Eigen::VectorXd& previous() const { return previous_; }
  /// P^l(x_l) on the finest mesh; positions() itself at the finest level.
  [[nodiscard]] Eigen::VectorXd finest_positions() const;
  /// Level `level` (below the finest) as a problem of its own.
  /// @throws std::out_of_range when `level` is not below the finest.
  [[nodiscard]] CoarseProblem coarse_problem(int level) const;

  /// Whether a step to `frame` at the current level is followed by settling steps: when the
  /// scene's frames are equilibria, the refine frame of a hierarchy and every frame of the
  /// finest level. A fixed-step scene never settles: its path has no equilibrium to settle to
  /// (a patch sliding down a slope) or the one settling reaches is not the path's (a twisted
  /// sheet's layers); a level entered by refinement then takes the refine frame's one step of Δt
  /// from its initializer.
  [[nodiscard]] bool frame_settles(int frame) const;
  /// One quasistatic step of the schedule. @throws std::logic_error when level_done().
  ProgressiveStep step(const Progress& progress = {});
  /// Moves to the next level from the current (done) one, telling `progress` (if set) each
  /// phase of the refinement as it starts. @throws std::logic_error when the level is not done
  /// or already the finest.
  void refine(const RefinementProgress& progress = {});
  /// The statistics of the refinement that entered the current level, by name
  /// (refinement_statistics.hpp); empty at level 0 and after a restore().
  [[nodiscard]] const std::map<std::string, double>& refinement_statistics() const {
    return entered_by_;
  }
  /// The schedule's position within the current level besides the frame: what restore() needs
  /// to continue exactly (stored with checkpoints as named scalars).
  [[nodiscard]] std::map<std::string, double> schedule_state() const;
  /// Resumes from a stored state: `level`, the frame reached (or being solved, when
  /// `iterations_in_frame` > 0), the level's positions (the Newton iterate after that many
  /// iterations of the frame) and xᵗ. With the schedule_state() of the same moment the run
  /// continues exactly as the uninterrupted one. Without it (an older checkpoint) a level
  /// restored at its refine frame takes one more settling step before it counts as done, and a
  /// frame in progress is started again from the stored iterate.
  void restore(int level, int frame, const Eigen::VectorXd& positions,
               const Eigen::VectorXd& previous, int iterations_in_frame = 0,
               const std::map<std::string, double>& schedule_state = {});

 private:
  /// Validates the hierarchies, resolves the tolerances, enters level 0 at its rest state.
  void initialize();
  void build_prolongations();
  /// Per level-(l+1) vertex of the system (shells, then colliders) its level-l parent, per
  /// level-l vertex its expansion colour, and the collapses in order: the shells' hierarchies
  /// renumbered into the systems.
  struct Expansion {
    std::vector<int> parent;
    std::vector<int> color;
    std::vector<std::array<int, 2>> collapses;  ///< (removed, survivor), level-(l+1) indices
  };
  [[nodiscard]] Expansion system_expansion(int level) const;
  /// The rest meshes and pin groups of the shells at system level `level` below the finest.
  [[nodiscard]] std::vector<LevelShellMesh> level_shells(int level) const;
  /// The colliders' rest meshes at system level `level`; empty when they have no hierarchies.
  [[nodiscard]] std::vector<TriMesh> level_colliders(int level) const;
  /// The level-`level` system below the finest.
  [[nodiscard]] std::unique_ptr<ShellSystem> make_coarse_system(int level) const;
  /// The name of the shell or collider of hierarchies_[hierarchy].
  [[nodiscard]] std::string mesh_name(int hierarchy) const;
  /// Whether hierarchies_ holds the colliders' after the shells'.
  [[nodiscard]] bool colliders_progressive() const {
    return hierarchies_.size() > finest_.shells().size();
  }
  /// Makes `level` the current level (its system, objective and stepper).
  void enter_level(int level);
  [[nodiscard]] NewtonSettings level_newton_settings(int level) const;
  [[nodiscard]] bool settles() const { return level_count_ > 1; }
  [[nodiscard]] bool frames_are_equilibria() const {
    return finest_.scene().solver.frame_solution == FrameSolution::equilibrium;
  }
  /// Why the settling that just ended did not reach an equilibrium, for a step whose change
  /// was `change`.
  [[nodiscard]] std::string settling_failure_message(double change) const;

  ProgressiveSettings settings_;
  ShellSystem finest_;
  /// The shells' hierarchies, then the colliders' (if they have any).
  std::vector<MeshHierarchy> hierarchies_;
  std::vector<HierarchyCacheUse> cache_uses_;
  int level_count_ = 1;
  int refine_frame_ = 1;
  double finest_tolerance_ = 0.0;
  double preview_tolerance_ = 0.0;
  /// Per level below the finest: P^l (to the finest mesh) and P^l_{l+1} (to the next level).
  std::vector<SystemProlongation> to_finest_;
  std::vector<SystemProlongation> to_next_;
  std::vector<RefinementStats> refinements_;
  std::vector<StrainCorrectionStats> strain_corrections_;
  std::map<std::string, double> entered_by_;

  int level_ = 0;
  int frame_ = 0;
  /// The frame reached (frame_) needs no more settling steps.
  bool settled_ = false;
  /// A settling of this level stopped (at max_settle_steps, or stalled) without passing its test.
  bool settling_failed_ = false;
  /// A judged step of a fixed-step scene at this level ended without converging.
  bool unconverged_step_ = false;
  int settle_steps_ = 0;
  /// The smallest settling change at the largest time step so far, and the steps since it last
  /// improved by 1 % (a stalled settling is given up).
  double best_change_ = 0.0;
  int stalled_steps_ = 0;
  /// Index of the settling time step (settling_time_step, next_settling_growth).
  int settle_growth_ = 0;
  /// Newton iterations already taken in the next step before a restore (0: start it afresh).
  int resumed_iterations_ = 0;
  std::unique_ptr<ShellSystem> coarse_system_;  ///< the current level's system below the finest
  std::unique_ptr<LevelStepper> stepper_;
  Eigen::VectorXd x_;
  Eigen::VectorXd previous_;
  /// The current frame's first xᵗ: friction's slip is measured from it through its settling.
  Eigen::VectorXd frame_start_;
};

}  // namespace psq
