#include "engine/sim/frame_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "engine/core/error.hpp"
#include "engine/scene/load_scale.hpp"

namespace psq {
namespace {

/// Penalty stiffness k of the first pull round, its growth per round and the rounds tried
/// before a frame gives up on reaching its targets (the scripted vertices then stay where the
/// last round left them, a safe state, and the next frame tries again). With the weights of
/// pull_weight, k = 1 already holds a pulled vertex as firmly as the stiffest shell's membrane
/// holds its own, so one round usually brings the targets within a safe direct move.
constexpr double kInitialPullStiffness = 1.0;
constexpr double kPullGrowth = 100.0;
constexpr int kMaxPullRounds = 6;

/// With contact or strain limits, Newton runs in chunks of this many iterations with the κ and
/// κ_s updates between them (the solver keeps its objective fixed within a call, so stiffnesses
/// may only change between).
constexpr int kStiffnessUpdateInterval = 10;

/// A step whose CCD bound is below this fraction of the Newton step creeps: a pair ahead of it
/// is so close that the barrier, too weak for the force pressing it, lets Newton aim through.
constexpr double kCreepingStep = 0.1;
/// Consecutive creeping steps after which a chunk ends early for a κ update: waiting for the
/// whole chunk lets a plate pressed onto a can's rim creep for tens of iterations between
/// doublings of κ (IPC updates κ after every iteration).
constexpr int kCreepingRun = 2;

/// Outer friction iterations (lag, solve) per frame at most; tilted_plane frames settle in 2–3.
constexpr int kMaxFrictionIterations = 5;

/// The stiffest in-plane stiffness of the scene's shells, E h / (1 − ν²) (N/m): the stiffness
/// of a membrane triangle against stretching, whatever its size.
double stiffest_membrane(const Scene& scene) {
  double stiffest = 0.0;
  for (const Shell& shell : scene.shells) {
    const Material& m = shell.material;
    stiffest = std::max(stiffest, m.youngs_modulus * m.thickness /
                                      (1.0 - m.poisson_ratio * m.poisson_ratio));
  }
  return stiffest;
}

/// Whether the CCD cut at least half of a solve's steps short (kCreepingStep).
bool steps_cut_by_ccd(const NewtonResult& solve) {
  int steps = 0;
  int cut = 0;
  for (const NewtonIteration& it : solve.history) {
    if (it.line_search_trials == 0) continue;
    ++steps;
    if (it.feasible_step < kCreepingStep) ++cut;
  }
  return steps > 0 && 2 * cut >= steps;
}

}  // namespace

void append_solve(NewtonResult& frame, NewtonResult solve) {
  const bool first = frame.history.empty();
  solve.iterations += first ? 0 : frame.iterations;
  solve.times += frame.times;
  solve.wall_seconds += frame.wall_seconds;
  solve.history.insert(solve.history.begin(), frame.history.begin(), frame.history.end());
  frame = std::move(solve);
}

NewtonSolver::Progress numbered_through_frame(NewtonSolver::Progress progress, int& taken) {
  if (!progress) return {};
  return [progress = std::move(progress), &taken](const NewtonIteration& it) {
    NewtonIteration numbered = it;
    numbered.iteration = taken;
    if (it.step_length > 0.0) ++taken;
    progress(numbered);
  };
}

FrameSolver::FrameSolver(const ShellSystem& system, IncrementalPotential& potential)
    : system_(system),
      potential_(potential),
      dofs_(system.fixed_dofs()),
      pull_weight_floor_(stiffest_membrane(system.scene())) {
  const Scene& scene = system.scene();
  if (contact_enabled(scene)) {
    contact_ = std::make_unique<ContactTerm>(system_);
    potential_.add_term(*contact_);
    if (friction_enabled(scene))
      friction_ = std::make_unique<FrictionTerm>(system_, scene.time.step);
  }
  if (strain_limit_enabled(scene)) {
    strain_limit_ = std::make_unique<StrainLimitTerm>(system_);
    strain_limit_->require_feasible(flat(system_.rest_mesh().vertices), "the rest state");
    potential_.add_term(*strain_limit_);
  }
}

void FrameSolver::begin_frame(Eigen::VectorXd& x, FrameRecord& record,
                              const NewtonSettings& settings,
                              const NewtonSolver::Progress& progress) {
  if (!contact_) {
    system_.apply_pins(x, record.time);
    if (!std::isfinite(potential_.value(x)))
      throw NumericalError(fmt::format(
          "frame {}: moving the pinned vertices to their scripted positions inverts, degenerates "
          "or stretches to the strain limit triangles next to them; use more frames (smaller "
          "steps of the motion)",
          record.frame));
    return;
  }
  contact_->potential().reset_stats();
  Eigen::VectorXd base_gradient;
  potential_.base_gradient(x, base_gradient);
  std::vector<bool> free(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) free[i] = dofs_.reduced(i) >= 0;
  contact_->initialize_stiffness(x, base_gradient, free, potential_.inertia_weight());
  if (move_scripted_vertices_if_safe(x, record.time)) return;

  // Pull the fixed components of the vertices whose targets moved; the others stay fixed, and
  // free components stay free.
  Eigen::VectorXd target = x;
  system_.apply_pins(target, record.time);
  std::vector<int> pulled;
  std::vector<Eigen::Vector3d> weights;
  std::vector<bool> held(x.size(), false);
  for (const PinnedVertex& p : system_.pinned()) {
    const bool moved = target.segment<3>(3 * p.vertex) != x.segment<3>(3 * p.vertex);
    if (!moved) {
      for (int c = 0; c < 3; ++c) held[3 * p.vertex + c] = p.fixes(c);
      continue;
    }
    pulled.push_back(p.vertex);
    const double mass = std::max(system_.dof_masses()[3 * p.vertex], contact_->average_mass());
    const double weight = std::max(potential_.inertia_weight() * mass, pull_weight_floor_);
    weights.push_back(Eigen::Vector3d(p.fixes(0) ? weight : 0.0, p.fixes(1) ? weight : 0.0,
                                      p.fixes(2) ? weight : 0.0));
  }
  pull_.set(std::move(pulled), target, std::move(weights));
  potential_.add_term(pull_);
  const DofMap pulled_dofs(held);
  pull_.set_stiffness(kInitialPullStiffness);
  for (int round = 0; round < kMaxPullRounds; ++round) {
    append_solve(record.newton, solve_in_chunks(x, pulled_dofs, settings, progress));
    ++record.kinematic_rounds;
    if (move_scripted_vertices_if_safe(x, record.time)) break;
    pull_.set_stiffness(kPullGrowth * pull_.stiffness());
  }
  potential_.remove_term(pull_);
}

bool FrameSolver::predict(Eigen::VectorXd& x, const Eigen::VectorXd& motion) {
  Eigen::VectorXd move = motion;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (dofs_.reduced(i) < 0) move[i] = 0.0;
  if (move.isZero(0.0)) return false;
  const double step = potential_.max_feasible_step(x, move);
  if (step <= 0.0) return false;
  Eigen::VectorXd predicted = x + step * move;
  if (!std::isfinite(potential_.value(predicted))) return false;
  x = std::move(predicted);
  return true;
}

bool FrameSolver::move_scripted_vertices_if_safe(Eigen::VectorXd& x, double time) {
  Eigen::VectorXd target = x;
  system_.apply_pins(target, time);
  const Eigen::VectorXd move = target - x;
  if (move.isZero(0.0)) return true;
  if (potential_.max_feasible_step(x, move) < 1.0 || !std::isfinite(potential_.value(target)))
    return false;
  x = std::move(target);
  return true;
}

NewtonResult FrameSolver::solve_in_chunks(Eigen::VectorXd& x, const DofMap& dofs,
                                          const NewtonSettings& settings,
                                          const NewtonSolver::Progress& progress) {
  const int interval = adaptive() ? kStiffnessUpdateInterval : settings.max_iterations;
  NewtonResult total;
  int done = 0;
  // Numbered within the whole solve, across the chunks.
  const NewtonSolver::Progress numbered = offset_progress(progress, done);
  NewtonSettings chunk = settings;
  // One watcher across the chunks, which are shorter than its window; a new one whenever a
  // stiffness update changes the objective, whose energies are then not comparable.
  RoundoffStagnation stagnation;
  // Only the barrier's κ answers creeping, and only where the CCD alone bounds the steps: with
  // strain limits the bound may be the limit's, which no κ relaxes, and stiffening the barrier
  // there only changes the path.
  if (contact_ && !strain_limit_) {
    chunk.max_cut_steps = kCreepingRun;
    chunk.cut_step = kCreepingStep;
  }
  while (true) {
    chunk.max_iterations = std::min(interval, settings.max_iterations - done);
    // An inner chunk's last iterate is judged by the next chunk's first iteration, which
    // assembles and factorizes there anyway: judging it here too would do that twice.
    chunk.judge_final_iterate =
        done + chunk.max_iterations < settings.max_iterations ? false : settings.judge_final_iterate;
    NewtonResult part = newton_.minimize(potential_, x, dofs, chunk, numbered, &stagnation);
    done += part.iterations;
    const bool creeping = steps_cut_by_ccd(part);
    append_solve(total, std::move(part));
    if (total.converged || total.stagnated || done >= settings.max_iterations) return total;
    if (update_stiffnesses(x, creeping)) stagnation = RoundoffStagnation{};
  }
}

bool FrameSolver::update_stiffnesses(const Eigen::VectorXd& x, bool steps_cut_by_ccd) {
  const bool contact_changed = contact_ && contact_->update_stiffness(x, steps_cut_by_ccd);
  const bool limit_changed = strain_limit_ && strain_limit_->update_stiffness(x);
  return contact_changed || limit_changed;
}

void FrameSolver::solve_held(Eigen::VectorXd& x, const Eigen::VectorXd& previous,
                             const Eigen::VectorXd& frame_start, FrameRecord& record,
                             const NewtonSettings& settings,
                             const NewtonSolver::Progress& progress) {
  if (!friction_) {
    append_solve(record.newton, solve_in_chunks(x, dofs_, settings, progress));
    return;
  }
  // IPC's outer loop: λ, T and w lagged at xᵗ, then at each solution, until the solution moves
  // less than the Newton tolerance (the same velocity-like measure) between outer iterations.
  // Without lagged contacts before and after a solve, re-solving would change nothing.
  potential_.add_term(*friction_);
  friction_->reset_seconds();
  friction_->lag(contact_->potential(), previous, frame_start);
  Eigen::VectorXd last_solution;
  double last_change = std::numeric_limits<double>::infinity();
  for (int iteration = 1;; ++iteration) {
    const bool had_contacts = friction_->contact_count() > 0;
    append_solve(record.newton, solve_in_chunks(x, dofs_, settings, progress));
    ++record.friction_iterations;
    const double change = last_solution.size() == x.size()
                              ? (x - last_solution).lpNorm<Eigen::Infinity>() / settings.step_scale
                              : std::numeric_limits<double>::infinity();
    const bool settled = change < settings.tolerance;
    if (!record.newton.converged || settled || iteration == kMaxFrictionIterations) break;
    Eigen::VectorXd lag_state = x;
    if (std::isfinite(change) && change >= 0.5 * last_change) {
      Eigen::VectorXd mid = 0.5 * (x + last_solution);
      if (std::isfinite(contact_->potential().value(mid))) lag_state = std::move(mid);
    }
    friction_->lag(contact_->potential(), lag_state, frame_start);
    if (!had_contacts && friction_->contact_count() == 0) break;
    last_solution = x;
    last_change = change;
  }
  potential_.remove_term(*friction_);
  record.friction_seconds += friction_->seconds();
}

void FrameSolver::finish_frame(const Eigen::VectorXd& x, FrameRecord& record) {
  // The scene's, not the system's: a coarse level's loads are the finest system's.
  record.load_scale = load_scale_at(system_.scene().load_scale, record.time);
  if (!system_.probes().empty()) {
    Eigen::VectorXd static_gradient;
    potential_.static_gradient(x, static_gradient);
    record.probes = read_probes(system_, x, static_gradient);
  }
  if (!contact_) return;
  Eigen::VectorXd target = x;
  system_.apply_pins(target, record.time);
  record.kinematic_offset = (target - x).lpNorm<Eigen::Infinity>();
  record.barrier_stiffness = contact_->stiffness();
  record.contact = contact_->potential().stats();
}

void FrameSolver::save_state(std::map<std::string, double>& state) const {
  if (contact_) contact_->save_state(state);
  if (strain_limit_) strain_limit_->save_state(state);
}

void FrameSolver::load_state(const std::map<std::string, double>& state) {
  if (contact_) contact_->load_state(state);
  if (strain_limit_) strain_limit_->load_state(state);
}

void FrameSolver::require_feasible(const Eigen::VectorXd& x, const std::string& what) const {
  if (strain_limit_) strain_limit_->require_feasible(x, what);
}

}  // namespace psq
