#include "engine/progressive/progressive_simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include "engine/contact/intersection_check.hpp"
#include "engine/core/error.hpp"
#include "engine/progressive/refinement_statistics.hpp"
#include "engine/sim/contact_term.hpp"
#include "engine/sim/solver_tolerance.hpp"
#include "engine/sim/strain_limit_term.hpp"

namespace psq {
namespace {

/// How much coarser than the current (more refined) levels a preview tolerance defaults to.
constexpr double kPreviewToleranceFactor = 10.0;

// Names of the schedule_state() scalars.
constexpr const char* kFramesDone = "progressive.frames_done";
constexpr const char* kSettleSteps = "progressive.settle_steps";
constexpr const char* kSettleGrowth = "progressive.settle_growth";
constexpr const char* kSettled = "progressive.settled";
constexpr const char* kLevelConverged = "progressive.level_converged";  // before settling_failed
constexpr const char* kSettlingFailed = "progressive.settling_failed";
constexpr const char* kBestChange = "progressive.best_change";
constexpr const char* kStalledSteps = "progressive.stalled_steps";
constexpr const char* kUnconvergedStep = "progressive.unconverged_step";

/// Settling steps at the largest time step in a row that do not bring the change 1 % below the
/// best one so far before a settling is given up: a state cycling between two answers (friction
/// lagged at each step's start, on the draped cloth: the same change to four digits, step after
/// step) would otherwise take max_settle_steps steps.
constexpr int kMaxStalledSettleSteps = 8;
constexpr double kSettleProgress = 0.99;

/// The Newton budget of a fixed-step scene's first step at a level entered by refinement, in the
/// scene's max_iterations. That step starts from the initializer, not from the previous frame, and
/// corrects the whole difference between the prolonged coarse answer and the fine one, which an
/// equilibrium scene's settling spreads over several steps (docs/benchmarks.md, twist_wrap).
constexpr int kEntryStepBudgets = 5;

/// The shells and colliders of `system` as named parts, for intersection listings.
std::vector<TrianglePart> triangle_parts(const ShellSystem& system) {
  std::vector<TrianglePart> parts;
  for (const ShellBlock& shell : system.shells())
    parts.push_back(
        {fmt::format("shell '{}'", shell.name), shell.first_triangle, shell.triangle_count});
  for (const ColliderBlock& collider : system.colliders())
    parts.push_back({fmt::format("collider '{}'", collider.name), collider.first_triangle,
                     collider.triangle_count});
  return parts;
}

void check_settings(const Scene& scene, const ProgressiveSettings& settings) {
  const auto fail = [&](const std::string& what) {
    throw InputError(fmt::format("{}: [hierarchy] {}", scene.source.string(), what));
  };
  const HierarchyOptions& s = settings.schedule;
  if (s.levels < 1) fail(fmt::format("levels must be at least 1 (got {})", s.levels));
  if (!(s.vertex_ratio > 0 && s.vertex_ratio < 1))
    fail(fmt::format("vertex_ratio must be in (0, 1) (got {})", s.vertex_ratio));
  if (s.preview_iterations < 1)
    fail(fmt::format("preview_iterations must be at least 1 (got {})", s.preview_iterations));
  if (s.preview_tolerance && !(*s.preview_tolerance > 0))
    fail(fmt::format("preview_tolerance must be positive (got {})", *s.preview_tolerance));
  if (s.refine_frame && (*s.refine_frame < 1 || *s.refine_frame > scene.time.frames))
    fail(fmt::format("refine_frame must be a frame in 1..{} (got {})", scene.time.frames,
                     *s.refine_frame));
  if (settings.max_settle_steps < 1)
    fail(fmt::format("max_settle_steps must be at least 1 (got {})", settings.max_settle_steps));
}

/// The level of a shell's own hierarchy used at system level `level`: shells with fewer levels
/// keep their coarsest mesh at the lowest system levels.
int shell_level(const MeshHierarchy& hierarchy, int level, int level_count) {
  return std::max(0, level - (level_count - hierarchy.level_count()));
}

}  // namespace

ProgressiveSettings ProgressiveSettings::from_scene(const Scene& scene) {
  ProgressiveSettings settings;
  settings.schedule = scene.hierarchy;
  return settings;
}

ProgressiveSimulation::ProgressiveSimulation(const Scene& scene,
                                             const ProgressiveSettings& settings)
    : settings_(settings), finest_(scene) {
  check_settings(scene, settings_);
  if (settings_.schedule.levels > 1)
    hierarchies_ = build_hierarchies(finest_, settings_, &cache_uses_);
  initialize();
}

ProgressiveSimulation::ProgressiveSimulation(const Scene& scene,
                                             const ProgressiveSettings& settings,
                                             std::vector<MeshHierarchy> hierarchies)
    : settings_(settings), finest_(scene), hierarchies_(std::move(hierarchies)) {
  check_settings(scene, settings_);
  initialize();
}

ProgressiveSimulation::~ProgressiveSimulation() = default;

void ProgressiveSimulation::initialize() {
  const Scene& scene = finest_.scene();
  const std::size_t shells = finest_.shells().size();
  const std::size_t colliders = finest_.colliders().size();
  if (!hierarchies_.empty() && hierarchies_.size() != shells &&
      hierarchies_.size() != shells + colliders)
    throw std::invalid_argument(
        fmt::format("ProgressiveSimulation: {} hierarchies for {} shells and {} colliders",
                    hierarchies_.size(), shells, colliders));
  for (std::size_t k = 0; k < hierarchies_.size(); ++k) {
    const MeshBlock& block = k < shells ? finest_.shells()[k] : finest_.colliders()[k - shells];
    if (hierarchies_[k].levels.empty() ||
        hierarchies_[k].finest().rest.vertex_count() != block.vertex_count)
      throw std::invalid_argument(
          fmt::format("ProgressiveSimulation: the hierarchy of {} '{}' does not end at its mesh",
                      k < shells ? "shell" : "collider", block.name));
    if (k < shells) level_count_ = std::max(level_count_, hierarchies_[k].level_count());
  }
  refine_frame_ = settings_.schedule.refine_frame.value_or(scene.time.frames);
  finest_tolerance_ = solver_tolerance(scene, bounding_box_diagonal(finest_.rest_mesh().vertices));
  preview_tolerance_ =
      settings_.schedule.preview_tolerance.value_or(kPreviewToleranceFactor * finest_tolerance_);
  build_prolongations();
  if (contact_enabled(scene)) {
    require_intersection_free(finest_.rest_mesh(), "the rest state", triangle_parts(finest_));
    for (int level = level_count_ - 2; level >= 0; --level) {
      const std::unique_ptr<ShellSystem> system = make_coarse_system(level);
      require_intersection_free(
          system->rest_mesh(),
          fmt::format("level {} of {} of the hierarchy (decimated rest state; use fewer "
                      "[hierarchy] levels or a larger vertex_ratio)",
                      level, level_count_),
          triangle_parts(*system));
    }
  }
  enter_level(0);
  x_ = flat(level_system().rest_mesh().vertices);
  previous_ = x_;
}

void ProgressiveSimulation::build_prolongations() {
  for (int level = 0; level + 1 < level_count_; ++level) {
    std::vector<ShellProlongation> finest_maps, next_maps;
    for (const MeshHierarchy& h : hierarchies_) {
      const int here = shell_level(h, level, level_count_);
      const int next = shell_level(h, level + 1, level_count_);
      const TriMesh& rest = h.levels[here].rest;
      finest_maps.push_back(
          here + 1 == h.level_count()
              ? identity_prolongation(rest)
              : ShellProlongation(rest, h.levels[here].finest, h.finest().rest.vertices));
      next_maps.push_back(next == here ? identity_prolongation(rest)
                                       : ShellProlongation(rest, h.levels[here].next_finer,
                                                           h.levels[next].rest.vertices));
    }
    const int collider_vertices =
        colliders_progressive() || finest_.colliders().empty()
            ? 0
            : finest_.rest_mesh().vertex_count() - finest_.colliders().front().first_vertex;
    to_finest_.emplace_back(std::move(finest_maps), collider_vertices);
    to_next_.emplace_back(std::move(next_maps), collider_vertices);
  }
}

ProgressiveSimulation::Expansion ProgressiveSimulation::system_expansion(int level) const {
  Expansion expansion;
  int coarse_first = 0;
  int fine_first = 0;
  for (const MeshHierarchy& h : hierarchies_) {
    const int here = shell_level(h, level, level_count_);
    const int next = shell_level(h, level + 1, level_count_);
    const int coarse_count = h.levels[here].rest.vertex_count();
    const int fine_count = h.levels[next].rest.vertex_count();
    if (next != here &&
        (static_cast<int>(h.levels[here].parent.size()) != fine_count ||
         static_cast<int>(h.levels[here].expansion_color.size()) != coarse_count ||
         static_cast<int>(h.levels[here].collapses.size()) != fine_count - coarse_count))
      throw std::invalid_argument(fmt::format(
          "ProgressiveSimulation: level {} of '{}' has no parents, expansion colours or "
          "collapses for the safe refinement",
          here, mesh_name(static_cast<int>(&h - hierarchies_.data()))));
    for (int v = 0; v < fine_count; ++v)
      expansion.parent.push_back(coarse_first + (next == here ? v : h.levels[here].parent[v]));
    if (next != here)
      for (const auto& [removed, survivor] : h.levels[here].collapses)
        expansion.collapses.push_back({fine_first + removed, fine_first + survivor});
    fine_first += fine_count;
    for (int k = 0; k < coarse_count; ++k)
      expansion.color.push_back(next == here ? 0 : h.levels[here].expansion_color[k]);
    coarse_first += coarse_count;
  }
  if (!colliders_progressive())  // the colliders keep their mesh at every level
    for (const ColliderBlock& collider : finest_.colliders())
      for (int v = 0; v < collider.vertex_count; ++v) {
        expansion.parent.push_back(coarse_first++);
        expansion.color.push_back(0);
      }
  return expansion;
}

NewtonSettings ProgressiveSimulation::level_newton_settings(int level) const {
  const Scene& scene = finest_.scene();
  NewtonSettings newton;
  newton.step_scale = scene.time.step;
  const bool finest = level + 1 == level_count_;
  newton.max_iterations =
      finest ? scene.solver.max_iterations : settings_.schedule.preview_iterations;
  newton.tolerance = finest ? finest_tolerance_ : preview_tolerance_;
  newton.project_on_demand = scene.solver.project_on_demand;
  // Below the finest level a step capped at preview_iterations is not meant to converge, and the
  // settling's change test decides when the level is done.
  newton.judge_final_iterate = finest;
  return newton;
}

std::vector<LevelShellMesh> ProgressiveSimulation::level_shells(int level) const {
  std::vector<LevelShellMesh> shells;
  for (std::size_t s = 0; s < finest_.shells().size(); ++s) {
    const MeshHierarchy& h = hierarchies_[s];
    const HierarchyLevel& shell = h.levels[shell_level(h, level, level_count_)];
    shells.push_back({shell.rest, shell.pin_group, finest_.shared_pins(static_cast<int>(s))});
  }
  return shells;
}

std::vector<TriMesh> ProgressiveSimulation::level_colliders(int level) const {
  std::vector<TriMesh> colliders;
  if (colliders_progressive())
    for (std::size_t k = finest_.shells().size(); k < hierarchies_.size(); ++k)
      colliders.push_back(
          hierarchies_[k].levels[shell_level(hierarchies_[k], level, level_count_)].rest);
  return colliders;
}

std::unique_ptr<ShellSystem> ProgressiveSimulation::make_coarse_system(int level) const {
  return std::make_unique<ShellSystem>(finest_.scene(), level_shells(level),
                                       level_colliders(level));
}

std::string ProgressiveSimulation::mesh_name(int hierarchy) const {
  const int shells = static_cast<int>(finest_.shells().size());
  return hierarchy < shells ? finest_.shells()[hierarchy].name
                            : finest_.colliders()[hierarchy - shells].name;
}

void ProgressiveSimulation::enter_level(int level) {
  const Scene& scene = finest_.scene();
  stepper_.reset();  // it refers to the level system replaced below
  if (level + 1 == level_count_) {
    coarse_system_.reset();
    stepper_ = std::make_unique<LevelStepper>(
        finest_, std::make_unique<LevelObjective>(finest_, scene.time.step),
        level_newton_settings(level));
  } else {
    coarse_system_ = make_coarse_system(level);
    stepper_ = std::make_unique<LevelStepper>(
        *coarse_system_,
        std::make_unique<ProxyObjective>(*coarse_system_, finest_, to_finest_[level],
                                         scene.time.step, settings_.gradient),
        level_newton_settings(level));
  }
  level_ = level;
  // Level 0 starts at the rest state (frame 0); a finer level at the refine frame, to be settled
  // (in a fixed-step scene: stepped once).
  settled_ = level == 0;
  settling_failed_ = false;
  unconverged_step_ = false;
  settle_steps_ = 0;
  best_change_ = std::numeric_limits<double>::infinity();
  stalled_steps_ = 0;
  settle_growth_ = 0;
}

const ShellSystem& ProgressiveSimulation::level_system() const { return stepper_->system(); }

double ProgressiveSimulation::tolerance() const { return stepper_->settings().tolerance; }

bool ProgressiveSimulation::level_done() const {
  const int last_frame = finest_level() ? frame_count() : refine_frame_;
  return frame_ == last_frame && settled_;
}

bool ProgressiveSimulation::frame_settles(int frame) const {
  if (!frames_are_equilibria()) return false;
  return (settles() && frame == refine_frame_) || finest_level();
}

Eigen::VectorXd ProgressiveSimulation::finest_positions() const {
  return finest_level() ? x_ : to_finest_[level_].apply(x_);
}

CoarseProblem ProgressiveSimulation::coarse_problem(int level) const {
  const SystemProlongation& to_finest = to_finest_.at(level);
  return {.shells = level_shells(level),
          .colliders = level_colliders(level),
          .loads = to_finest.apply_linear_transpose(finest_.loads()),
          .to_finest = to_finest,
          .finest_rest = finest_.rest_mesh().vertices};
}

ProgressiveStep ProgressiveSimulation::step(const Progress& progress) {
  if (level_done())
    throw std::logic_error(fmt::format("ProgressiveSimulation::step: level {} is done", level_));
  ProgressiveStep out;
  out.level = level_;
  out.settling = !settled_;
  const int frame = out.settling ? frame_ : frame_ + 1;
  const double time_step = out.settling
                               ? settling_time_step(finest_.scene().time.step, settle_growth_)
                               : finest_.scene().time.step;
  // Every level's external force is the finest system's (ProxyElastics), at the frame's loading.
  finest_.set_load_time(frame * finest_.scene().time.step);
  // Newton iterates on x_ itself, so that positions() is the current iterate while it runs.
  const int iterations_done = std::exchange(resumed_iterations_, 0);
  if (iterations_done == 0) previous_ = x_;
  if (!out.settling && iterations_done == 0) frame_start_ = previous_;
  // The refine frame's one step of Δt at a level entered by refinement (a fixed-step scene).
  const bool entry_step = out.settling && !frames_are_equilibria();
  NewtonSettings settings = stepper_->settings();
  // Below the finest level of a fixed-step scene the refine frame's step is the state the next
  // level is prolonged from, and no settling converges it: capped at preview_iterations it would
  // hand the refinement a state far from the level's answer, which the finer level then has to
  // correct in steps its CCD cuts short. Solved to the level's tolerance, it costs coarse
  // iterations only.
  if (!frames_are_equilibria() && !finest_level() && frame == refine_frame_) {
    settings.max_iterations = finest_.scene().solver.max_iterations;
    settings.judge_final_iterate = true;
  }
  if (entry_step) settings.max_iterations *= kEntryStepBudgets;
  out.frame = stepper_->step(
      previous_, x_, frame, time_step, iterations_done, settings,
      [&](const NewtonIteration& it) {
        if (progress) progress(level_, frame, it);
      },
      frame_start_);
  out.change = (x_ - previous_).lpNorm<Eigen::Infinity>() / finest_.scene().time.step;
  frame_ = frame;
  const bool converged_at_start = out.frame.newton.converged && out.frame.newton.iterations == 0;
  if (entry_step) {
    // One step of Δt, as any frame of the path.
    settled_ = true;
    ++settle_steps_;
    out.judged = finest_level();
    out.converged = out.frame.newton.converged;
  } else if (out.settling) {
    // At the finest level the step that ends a settling must itself be solved to the tolerance;
    // steps before it may stop at their budget on the way.
    const bool done = settling_done(settle_growth_, out.change, tolerance()) &&
                      (!finest_level() || out.frame.newton.converged);
    ++settle_steps_;
    if (settle_growth_ >= kSettlingGrowthSteps) {
      const bool progress_made = out.change < kSettleProgress * best_change_;
      stalled_steps_ = progress_made ? 0 : stalled_steps_ + 1;
      best_change_ = std::min(best_change_, out.change);
    }
    settle_growth_ = next_settling_growth(settle_growth_, converged_at_start);
    settled_ = done || settle_steps_ >= settings_.max_settle_steps ||
               stalled_steps_ >= kMaxStalledSettleSteps;
    if (settled_ && !done) {
      settling_failed_ = true;
      out.settling_failure = settling_failure_message(out.change);
    }
    out.equilibrium = done;
    if (done) out.frame.static_residual = out.frame.newton.step_norm;
    out.judged = finest_level() && settled_;
    out.converged = out.frame.newton.converged && done;
  } else {
    // The frame's step is the settling schedule's first, at Δt.
    settled_ = !frame_settles(frame);
    settle_steps_ = 0;
    best_change_ = std::numeric_limits<double>::infinity();
    stalled_steps_ = 0;
    settle_growth_ = next_settling_growth(0, converged_at_start);
    out.judged = finest_level();
    out.converged = out.frame.newton.converged;
  }
  // In a fixed-step scene each judged step is its frame's answer; in an equilibrium scene the
  // frame's settling judges it (settling_failed_).
  if (!frames_are_equilibria() && out.judged && !out.converged) unconverged_step_ = true;
  return out;
}

std::string ProgressiveSimulation::settling_failure_message(double change) const {
  if (stalled_steps_ >= kMaxStalledSettleSteps)
    return fmt::format(
        "level {} frame {}: the settling to a static equilibrium stalled: over {} steps at the "
        "largest pseudo time step (Δt·4^{}) the change ‖x − xᵗ‖∞/Δt did not fall below {:.3e} "
        "m/s (last {:.3e} m/s, tolerance {:.3g} m/s). A structure that keeps moving at that "
        "step is not held against its loads: check that its pins, colliders and friction "
        "support it",
        level_, frame_, kMaxStalledSettleSteps, kSettlingGrowthSteps, best_change_, change,
        tolerance());
  return fmt::format(
      "level {} frame {}: the settling to a static equilibrium stopped after {} steps with the "
      "change ‖x − xᵗ‖∞/Δt at {:.3e} m/s (tolerance {:.3g} m/s)",
      level_, frame_, settle_steps_, change, tolerance());
}

void ProgressiveSimulation::refine(const RefinementProgress& progress) {
  if (level_ + 1 >= level_count_)
    throw std::logic_error("ProgressiveSimulation::refine: already at the finest level");
  if (!level_done())
    throw std::logic_error(
        fmt::format("ProgressiveSimulation::refine: level {} is not done", level_));
  const auto start = std::chrono::steady_clock::now();
  Eigen::VectorXd next = to_next_[level_].apply(x_);
  const Eigen::VectorXd coarse = x_;
  const bool contact = contact_enabled(finest_.scene());
  const bool strain_limited = strain_limit_enabled(finest_.scene());
  const Expansion expansion = contact || strain_limited ? system_expansion(level_) : Expansion{};
  enter_level(level_ + 1);
  level_system().apply_pins(next, refine_frame_ * finest_.scene().time.step);
  std::optional<RefinementStats> safe_initialization;
  std::optional<StrainCorrectionStats> strain_correction;
  if (contact) {
    safe_initialization.emplace();
    next = safe_initialize(level_system(), expansion.parent, expansion.color, coarse,
                           expansion.collapses, to_next_[level_ - 1].apply_linear(coarse), next,
                           level_, *safe_initialization, progress);
    refinements_.push_back(*safe_initialization);
  }
  if (strain_limited) {
    if (progress) progress("strain-limit correction");
    std::vector<bool> inserted(next.size() / 3, false);
    for (const auto& [removed, survivor] : expansion.collapses) inserted[removed] = true;
    strain_correction = correct_strain_limits(level_system(), inserted, level_, next);
    strain_corrections_.push_back(*strain_correction);
  }
  x_ = std::move(next);
  previous_ = x_;
  frame_start_ = x_;
  entered_by_ = named_refinement_statistics(
      safe_initialization, strain_correction,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

std::map<std::string, double> ProgressiveSimulation::schedule_state() const {
  std::map<std::string, double> state{{kFramesDone, frame_},
                                      {kSettleSteps, settle_steps_},
                                      {kSettleGrowth, settle_growth_},
                                      {kSettled, settled_ ? 1.0 : 0.0},
                                      {kSettlingFailed, settling_failed_ ? 1.0 : 0.0},
                                      {kUnconvergedStep, unconverged_step_ ? 1.0 : 0.0},
                                      {kStalledSteps, stalled_steps_}};
  // Stored values must be finite; none is stored before the first step at the largest Δt.
  if (std::isfinite(best_change_)) state[kBestChange] = best_change_;
  stepper_->frame_solver().save_state(state);
  return state;
}

void ProgressiveSimulation::restore(int level, int frame, const Eigen::VectorXd& positions,
                                    const Eigen::VectorXd& previous, int iterations_in_frame,
                                    const std::map<std::string, double>& schedule_state) {
  if (level < 0 || level >= level_count_)
    throw std::invalid_argument(
        fmt::format("ProgressiveSimulation::restore: level {} of {}", level, level_count_));
  const int last_frame = level + 1 < level_count_ ? refine_frame_ : frame_count();
  const int first_frame = level == 0 ? 0 : refine_frame_;
  if (frame < first_frame || frame > last_frame)
    throw std::invalid_argument(
        fmt::format("ProgressiveSimulation::restore: frame {} is outside level {}'s frames {}..{}",
                    frame, level, first_frame, last_frame));
  if (iterations_in_frame < 0)
    throw std::invalid_argument(fmt::format(
        "ProgressiveSimulation::restore: {} iterations in the frame", iterations_in_frame));
  enter_level(level);
  entered_by_.clear();
  const Eigen::Index size = level_system().rest_mesh().vertices.size();
  if (positions.size() != size || previous.size() != size)
    throw std::invalid_argument(fmt::format(
        "ProgressiveSimulation::restore: level {} has {} unknowns, got {} positions and {} "
        "previous",
        level, size, positions.size(), previous.size()));
  x_ = positions;
  previous_ = previous;
  frame_start_ = previous;
  stepper_->frame_solver().load_state(schedule_state);
  const auto stored = [&](const char* name) -> std::optional<double> {
    const auto found = schedule_state.find(name);
    if (found == schedule_state.end()) return std::nullopt;
    return found->second;
  };
  const auto frames_done = stored(kFramesDone), settle_steps = stored(kSettleSteps),
             settled = stored(kSettled), failed = stored(kSettlingFailed),
             converged = stored(kLevelConverged);
  if (frames_done && settle_steps && settled && (failed || converged)) {
    frame_ = static_cast<int>(*frames_done);
    settle_steps_ = static_cast<int>(*settle_steps);
    best_change_ = stored(kBestChange).value_or(std::numeric_limits<double>::infinity());
    stalled_steps_ = static_cast<int>(stored(kStalledSteps).value_or(0.0));
    // Stores written before the growth index existed grew Δt once per settling step.
    settle_growth_ = static_cast<int>(
        stored(kSettleGrowth).value_or(std::min(settle_steps_, kSettlingGrowthSteps)));
    settled_ = *settled != 0.0;
    // Stores written before settling_failed kept whether the level's one settling converged.
    settling_failed_ = failed ? *failed != 0.0 : settled_ && *converged == 0.0;
    unconverged_step_ = stored(kUnconvergedStep).value_or(0.0) != 0.0;
    resumed_iterations_ = iterations_in_frame;
    return;
  }
  frame_ = frame;
  settled_ = !frame_settles(frame) || (settles() && frame > refine_frame_);
}

}  // namespace psq
