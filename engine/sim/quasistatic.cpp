#include "engine/sim/quasistatic.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "engine/core/error.hpp"

namespace psq {
namespace {

/// Penalty stiffness k of the first pull round, its growth per round and the rounds tried
/// before a frame gives up on reaching its targets (the scripted vertices then stay where the
/// last round left them, a safe state, and the next frame tries again).
constexpr double kInitialPullStiffness = 1e4;
constexpr double kPullGrowth = 100.0;
constexpr int kMaxPullRounds = 6;

/// With contact or strain limits, Newton runs in chunks of this many iterations with the κ and
/// κ_s updates between them (the solver keeps its objective fixed within a call, so stiffnesses
/// may only change between).
constexpr int kStiffnessUpdateInterval = 10;

/// adaptive_state()'s names, inside a settling step, of its growth index and of the frame's
/// iterations taken before it started (to tell, after a restore, whether it took any).
constexpr const char* kSettleGrowthState = "settling.growth";
constexpr const char* kSettleStepStartState = "settling.step_start";

/// Outer friction iterations (lag, solve) per frame at most; tilted_plane frames settle in 2–3.
constexpr int kMaxFrictionIterations = 5;

/// Adds a solve to a frame's Newton record: iterations, history and times accumulate; the
/// verdict and the final values are the last solve's.
void append_solve(NewtonResult& frame, NewtonResult solve) {
  const bool first = frame.history.empty();
  solve.iterations += first ? 0 : frame.iterations;
  solve.times += frame.times;
  solve.wall_seconds += frame.wall_seconds;
  solve.history.insert(solve.history.begin(), frame.history.begin(), frame.history.end());
  frame = std::move(solve);
}

/// Moves the pinned vertices of x to their scripted positions at frame·Δt; throws
/// NumericalError when that makes `objective` non-finite.
void apply_pins_checked(Objective& objective, const ShellSystem& system, int frame,
                        Eigen::VectorXd& x) {
  system.apply_pins(x, frame * system.scene().time.step);
  if (!std::isfinite(objective.value(x)))
    throw NumericalError(fmt::format(
        "frame {}: moving the pinned vertices to their scripted positions inverts, degenerates "
        "or stretches to the strain limit triangles next to them; use more frames (smaller "
        "steps of the motion)",
        frame));
}

/// `progress` with its records numbered through the whole frame, from `taken` iterations on
/// (those before a restore): a frame takes several Newton solves (pull rounds, κ chunks,
/// friction iterations, settling steps), and a snapshot's iteration count must cover them all.
/// Empty when `progress` is.
NewtonSolver::Progress numbered_through_frame(NewtonSolver::Progress progress, int& taken) {
  if (!progress) return {};
  return [progress = std::move(progress), &taken](const NewtonIteration& it) {
    NewtonIteration numbered = it;
    numbered.iteration = taken;
    if (it.step_length > 0.0) ++taken;
    progress(numbered);
  };
}

}  // namespace

NewtonResult solve_pinned_step(NewtonSolver& newton, Objective& objective,
                               const ShellSystem& system, const DofMap& dofs,
                               const NewtonSettings& settings, int frame, Eigen::VectorXd& x,
                               const NewtonSolver::Progress& progress) {
  apply_pins_checked(objective, system, frame, x);
  return newton.minimize(objective, x, dofs, settings, progress);
}

QuasistaticSimulation::QuasistaticSimulation(const Scene& scene)
    : system_(scene),
      potential_(system_, scene.time.step),
      dofs_(system_.rest_mesh().vertex_count(), system_.pinned_vertex_indices()),
      x_(flat(system_.rest_mesh().vertices)),
      previous_(x_) {
  settings_.step_scale = scene.time.step;
  settings_.max_iterations = scene.solver.max_iterations;
  settings_.tolerance =
      scene.solver.tolerance.value_or(1e-4 * bounding_box_diagonal(system_.rest_mesh().vertices));
  if (contact_enabled(scene)) {
    contact_ = std::make_unique<ContactTerm>(system_);
    potential_.add_term(*contact_);
    if (friction_enabled(scene))
      friction_ = std::make_unique<FrictionTerm>(system_, scene.time.step);
  }
  if (strain_limit_enabled(scene)) {
    strain_limit_ = std::make_unique<StrainLimitTerm>(system_);
    strain_limit_->require_feasible(x_, "the rest state");
    potential_.add_term(*strain_limit_);
  }
}

void QuasistaticSimulation::begin_contact_frame(FrameRecord& record, const NewtonSettings& settings,
                                                const NewtonSolver::Progress& progress) {
  contact_->potential().reset_stats();
  Eigen::VectorXd base_gradient;
  potential_.base_gradient(x_, base_gradient);
  std::vector<bool> free(x_.size());
  for (Eigen::Index i = 0; i < x_.size(); ++i) free[i] = dofs_.reduced(i) >= 0;
  contact_->initialize_stiffness(x_, base_gradient, free, potential_.inertia_weight());
  if (move_scripted_vertices_if_safe(record.time)) return;

  // Pull the vertices whose targets moved; the others stay fixed.
  Eigen::VectorXd target = x_;
  system_.apply_pins(target, record.time);
  std::vector<int> pulled, held;
  std::vector<double> weights;
  for (const PinnedVertex& p : system_.pinned()) {
    if (target.segment<3>(3 * p.vertex) == x_.segment<3>(3 * p.vertex)) {
      held.push_back(p.vertex);
      continue;
    }
    pulled.push_back(p.vertex);
    const double mass = std::max(system_.dof_masses()[3 * p.vertex], contact_->average_mass());
    weights.push_back(potential_.inertia_weight() * mass);
  }
  pull_.set(std::move(pulled), target, std::move(weights));
  potential_.add_term(pull_);
  const DofMap pulled_dofs(system_.rest_mesh().vertex_count(), held);
  pull_.set_stiffness(kInitialPullStiffness);
  for (int round = 0; round < kMaxPullRounds; ++round) {
    append_solve(record.newton, solve_in_chunks(pulled_dofs, settings, progress));
    ++record.kinematic_rounds;
    if (move_scripted_vertices_if_safe(record.time)) break;
    pull_.set_stiffness(kPullGrowth * pull_.stiffness());
  }
  potential_.remove_term(pull_);
}

bool QuasistaticSimulation::move_scripted_vertices_if_safe(double time) {
  Eigen::VectorXd target = x_;
  system_.apply_pins(target, time);
  const Eigen::VectorXd move = target - x_;
  if (move.isZero(0.0)) return true;
  if (potential_.max_feasible_step(x_, move) < 1.0 || !std::isfinite(potential_.value(target)))
    return false;
  x_ = std::move(target);
  return true;
}

NewtonResult QuasistaticSimulation::solve_in_chunks(const DofMap& dofs,
                                                    const NewtonSettings& settings,
                                                    const NewtonSolver::Progress& progress) {
  const int interval =
      contact_ || strain_limit_ ? kStiffnessUpdateInterval : settings.max_iterations;
  NewtonResult total;
  int done = 0;
  // Numbered within the whole solve, across the chunks.
  const NewtonSolver::Progress numbered = offset_progress(progress, done);
  NewtonSettings chunk = settings;
  while (true) {
    chunk.max_iterations = std::min(interval, settings.max_iterations - done);
    NewtonResult part = newton_.minimize(potential_, x_, dofs, chunk, numbered);
    done += part.iterations;
    append_solve(total, std::move(part));
    if (total.converged || total.stagnated || done >= settings.max_iterations) return total;
    update_stiffnesses();
  }
}

void QuasistaticSimulation::solve_contact_frame(FrameRecord& record, const NewtonSettings& settings,
                                                const NewtonSolver::Progress& progress) {
  if (!friction_) {
    append_solve(record.newton, solve_in_chunks(dofs_, settings, progress));
    return;
  }
  // IPC's outer loop: λ, T and w lagged at xᵗ, then at each solution, until the solution moves
  // less than the Newton tolerance (the same velocity-like measure) between outer iterations.
  // Without lagged contacts before and after a solve, re-solving would change nothing.
  potential_.add_term(*friction_);
  friction_->reset_seconds();
  friction_->lag(contact_->potential(), previous_, frame_start_);
  Eigen::VectorXd last_solution;
  for (int iteration = 1;; ++iteration) {
    const bool had_contacts = friction_->contact_count() > 0;
    append_solve(record.newton, solve_in_chunks(dofs_, settings, progress));
    ++record.friction_iterations;
    const bool settled =
        last_solution.size() == x_.size() &&
        (x_ - last_solution).lpNorm<Eigen::Infinity>() / settings.step_scale < settings.tolerance;
    if (!record.newton.converged || settled || iteration == kMaxFrictionIterations) break;
    friction_->lag(contact_->potential(), x_, frame_start_);
    if (!had_contacts && friction_->contact_count() == 0) break;
    last_solution = x_;
  }
  potential_.remove_term(*friction_);
  record.friction_seconds = friction_->seconds();
}

void QuasistaticSimulation::update_stiffnesses() {
  if (contact_) contact_->update_stiffness(x_);
  if (strain_limit_) strain_limit_->update_stiffness(x_);
}

void QuasistaticSimulation::finish_contact_frame(FrameRecord& record) {
  Eigen::VectorXd target = x_;
  system_.apply_pins(target, record.time);
  record.kinematic_offset = (target - x_).lpNorm<Eigen::Infinity>();
  record.barrier_stiffness = contact_->stiffness();
  record.contact = contact_->potential().stats();
}

void QuasistaticSimulation::solve_held_frame(FrameRecord& record, const NewtonSettings& settings,
                                             const NewtonSolver::Progress& progress) {
  if (contact_)
    solve_contact_frame(record, settings, progress);
  else
    append_solve(record.newton, solve_in_chunks(dofs_, settings, progress));
}

void QuasistaticSimulation::settle(FrameRecord& record, const NewtonSettings& settings,
                                   const NewtonSolver::Progress& progress, bool continue_restored,
                                   int restored_iterations) {
  const double time_step = system_.scene().time.step;
  for (bool restored = continue_restored;; restored = false) {
    NewtonSettings budget = settings;
    budget.max_iterations = settings.max_iterations - record.newton.iterations;
    if (budget.max_iterations < 1) {
      record.newton.converged = false;
      break;
    }
    if (!restored) {
      previous_ = x_;
      settle_step_start_ = restored_iterations + record.newton.iterations;
    }
    potential_.set_previous(previous_);
    potential_.set_time_step(settling_time_step(time_step, settle_growth_));
    solve_held_frame(record, budget, progress);
    ++record.settle_steps;
    const double change = (x_ - previous_).lpNorm<Eigen::Infinity>() / time_step;
    const bool done = settling_done(settle_growth_, change, settings.tolerance);
    settle_growth_ = next_settling_growth(
        settle_growth_, record.newton.converged &&
                            restored_iterations + record.newton.iterations == settle_step_start_);
    if (!record.newton.converged) break;
    if (done) {
      record.static_residual = record.newton.step_norm;
      break;
    }
  }
  potential_.set_time_step(time_step);
}

FrameRecord QuasistaticSimulation::step(const Progress& progress) {
  FrameRecord record;
  record.frame = frame_ + 1;
  record.time = record.frame * system_.scene().time.step;
  const int resumed_iterations = std::exchange(resumed_iterations_, 0);
  const bool resumed_in_settling = resumed_iterations > 0 && settle_growth_ > 0;
  if (resumed_iterations == 0) previous_ = x_;
  frame_start_ = previous_;
  potential_.set_previous(previous_);
  const int frame_number = record.frame;
  NewtonSettings settings = settings_;
  settings.max_iterations -= resumed_iterations;
  NewtonSolver::Progress frame_progress;
  if (progress) frame_progress = [&](const NewtonIteration& it) { progress(frame_number, it); };
  int iterations_taken = resumed_iterations;
  const NewtonSolver::Progress counted_progress =
      numbered_through_frame(frame_progress, iterations_taken);
  // Newton iterates on x_ itself, so that positions() is the current iterate while it runs.
  if (!resumed_in_settling) {
    if (contact_) {
      begin_contact_frame(record, settings, counted_progress);
    } else {
      apply_pins_checked(potential_, system_, record.frame, x_);
    }
    solve_held_frame(record, settings, counted_progress);
    // The frame's step was the settling schedule's first, at Δt.
    settle_growth_ = next_settling_growth(
        0, record.newton.converged && resumed_iterations + record.newton.iterations == 0);
  }
  if (system_.scene().solver.frame_solution == FrameSolution::equilibrium &&
      (record.newton.converged || resumed_in_settling))
    settle(record, settings, counted_progress, resumed_in_settling, resumed_iterations);
  settle_growth_ = 0;
  if (contact_) finish_contact_frame(record);
  record.newton.iterations += resumed_iterations;
  frame_ = record.frame;
  record.elastic_energy = potential_.elastic_energy(x_);
  return record;
}

std::map<std::string, double> QuasistaticSimulation::adaptive_state() const {
  std::map<std::string, double> state;
  if (contact_) contact_->save_state(state);
  if (strain_limit_) strain_limit_->save_state(state);
  if (settle_growth_ > 0) {
    state[kSettleGrowthState] = settle_growth_;
    state[kSettleStepStartState] = settle_step_start_;
  }
  return state;
}

void QuasistaticSimulation::restore(int frame, const Eigen::VectorXd& positions,
                                    const Eigen::VectorXd& previous, int iterations_in_frame,
                                    const std::map<std::string, double>& adaptive_state) {
  const bool in_progress = iterations_in_frame > 0;
  if (positions.size() != x_.size() || previous.size() != x_.size())
    throw std::invalid_argument(fmt::format("restore: {} and {} values for {} unknowns",
                                            positions.size(), previous.size(), x_.size()));
  if (frame < (in_progress ? 1 : 0) || frame > frame_count())
    throw std::invalid_argument(fmt::format("restore: frame {} outside [{}, {}]", frame,
                                            in_progress ? 1 : 0, frame_count()));
  if (iterations_in_frame < 0 || iterations_in_frame > settings_.max_iterations)
    throw std::invalid_argument(fmt::format("restore: {} iterations done, the limit is {}",
                                            iterations_in_frame, settings_.max_iterations));
  if (strain_limit_)
    strain_limit_->require_feasible(positions,
                                    fmt::format("the restored state of frame {}", frame));
  if (contact_) contact_->load_state(adaptive_state);
  if (strain_limit_) strain_limit_->load_state(adaptive_state);
  x_ = positions;
  previous_ = previous;
  frame_ = in_progress ? frame - 1 : frame;
  resumed_iterations_ = iterations_in_frame;
  const auto growth = adaptive_state.find(kSettleGrowthState);
  const auto step_start = adaptive_state.find(kSettleStepStartState);
  const bool settling = in_progress && growth != adaptive_state.end();
  settle_growth_ = settling ? static_cast<int>(growth->second) : 0;
  settle_step_start_ = settling && step_start != adaptive_state.end()
                           ? static_cast<int>(step_start->second)
                           : iterations_in_frame;
}

}  // namespace psq
