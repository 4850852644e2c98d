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
    if (total.converged || done >= settings.max_iterations) return total;
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
  friction_->lag(contact_->potential(), previous_, previous_);
  Eigen::VectorXd last_solution;
  while (true) {
    const bool had_contacts = friction_->contact_count() > 0;
    append_solve(record.newton, solve_in_chunks(dofs_, settings, progress));
    ++record.friction_iterations;
    const bool settled =
        last_solution.size() == x_.size() &&
        (x_ - last_solution).lpNorm<Eigen::Infinity>() / settings.step_scale < settings.tolerance;
    if (!record.newton.converged || settled || record.friction_iterations == kMaxFrictionIterations)
      break;
    friction_->lag(contact_->potential(), x_, previous_);
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

FrameRecord QuasistaticSimulation::step(const Progress& progress) {
  FrameRecord record;
  record.frame = frame_ + 1;
  record.time = record.frame * system_.scene().time.step;
  const int resumed_iterations = std::exchange(resumed_iterations_, 0);
  if (resumed_iterations == 0) previous_ = x_;
  potential_.set_previous(previous_);
  const int frame_number = record.frame;
  NewtonSettings settings = settings_;
  settings.max_iterations -= resumed_iterations;
  NewtonSolver::Progress frame_progress;
  if (progress) frame_progress = [&](const NewtonIteration& it) { progress(frame_number, it); };
  // Numbered within the whole frame, across a restore.
  const NewtonSolver::Progress counted_progress =
      offset_progress(frame_progress, resumed_iterations);
  // Newton iterates on x_ itself, so that positions() is the current iterate while it runs.
  if (contact_) {
    begin_contact_frame(record, settings, counted_progress);
    solve_contact_frame(record, settings, counted_progress);
    finish_contact_frame(record);
  } else {
    apply_pins_checked(potential_, system_, record.frame, x_);
    record.newton = solve_in_chunks(dofs_, settings, counted_progress);
  }
  record.newton.iterations += resumed_iterations;
  frame_ = record.frame;
  record.elastic_energy = potential_.elastic_energy(x_);
  return record;
}

std::map<std::string, double> QuasistaticSimulation::adaptive_state() const {
  std::map<std::string, double> state;
  if (contact_) contact_->save_state(state);
  if (strain_limit_) strain_limit_->save_state(state);
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
}

}  // namespace psq
