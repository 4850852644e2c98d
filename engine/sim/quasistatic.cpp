#include "engine/sim/quasistatic.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "engine/core/error.hpp"
#include "engine/sim/solver_tolerance.hpp"

namespace psq {
namespace {

/// adaptive_state()'s names, inside a settling step, of its growth index and of the frame's
/// iterations taken before it started (to tell, after a restore, whether it took any).
constexpr const char* kSettleGrowthState = "settling.growth";
constexpr const char* kSettleStepStartState = "settling.step_start";

}  // namespace

QuasistaticSimulation::QuasistaticSimulation(const Scene& scene)
    : system_(scene),
      potential_(system_, scene.time.step),
      frame_solver_(system_, potential_),
      x_(flat(system_.rest_mesh().vertices)),
      previous_(x_) {
  configure_newton();
}

QuasistaticSimulation::QuasistaticSimulation(const Scene& scene,
                                             const std::vector<LevelShellMesh>& shells,
                                             const std::vector<TriMesh>& colliders,
                                             const Eigen::VectorXd& loads)
    : system_(scene, shells, colliders),
      potential_(system_, scene.time.step),
      frame_solver_(system_, potential_),
      x_(flat(system_.rest_mesh().vertices)),
      previous_(x_) {
  system_.set_loads(loads);
  configure_newton();
}

void QuasistaticSimulation::configure_newton() {
  const Scene& scene = system_.scene();
  settings_.step_scale = scene.time.step;
  settings_.max_iterations = scene.solver.max_iterations;
  settings_.project_on_demand = scene.solver.project_on_demand;
  settings_.tolerance =
      solver_tolerance(scene, bounding_box_diagonal(system_.rest_mesh().vertices));
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
    frame_solver_.solve_held(x_, previous_, frame_start_, record, budget, progress);
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
  system_.set_load_time(record.time);
  const int resumed_iterations = std::exchange(resumed_iterations_, 0);
  const bool resumed_in_settling = resumed_iterations > 0 && settle_growth_ > 0;
  // A fixed-step frame starts from the last frame's answer moved on by that frame's motion; a
  // settled frame's last step barely moved, so its prediction is nil. The motion is x − xᵗ,
  // which a snapshot between frames holds, so a resumed run predicts as the uninterrupted one.
  const bool fresh_frame = resumed_iterations == 0;
  const Eigen::VectorXd last_motion =
      fresh_frame ? Eigen::VectorXd(x_ - previous_) : Eigen::VectorXd();
  if (fresh_frame) previous_ = x_;
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
    if (fresh_frame) record.predicted = frame_solver_.predict(x_, last_motion);
    frame_solver_.begin_frame(x_, record, settings, counted_progress);
    frame_solver_.solve_held(x_, previous_, frame_start_, record, settings, counted_progress);
    // The frame's step was the settling schedule's first, at Δt.
    settle_growth_ = next_settling_growth(
        0, record.newton.converged && resumed_iterations + record.newton.iterations == 0);
  }
  if (frame_settles(record.frame) && (record.newton.converged || resumed_in_settling))
    settle(record, settings, counted_progress, resumed_in_settling, resumed_iterations);
  settle_growth_ = 0;
  frame_solver_.finish_frame(x_, record);
  record.newton.iterations += resumed_iterations;
  frame_ = record.frame;
  record.elastic_energy = potential_.elastic_energy(x_);
  return record;
}

bool QuasistaticSimulation::frame_settles(int frame) const {
  return system_.scene().solver.frame_solution == FrameSolution::equilibrium &&
         frame >= first_settled_frame_;
}

std::map<std::string, double> QuasistaticSimulation::adaptive_state() const {
  std::map<std::string, double> state;
  frame_solver_.save_state(state);
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
  frame_solver_.require_feasible(positions, fmt::format("the restored state of frame {}", frame));
  frame_solver_.load_state(adaptive_state);
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
