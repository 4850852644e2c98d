#include "engine/progressive/level_stepper.hpp"

namespace psq {

LevelStepper::LevelStepper(const ShellSystem& system, std::unique_ptr<LevelObjective> objective,
                           const NewtonSettings& settings)
    : system_(system),
      objective_(std::move(objective)),
      dofs_(system.rest_mesh().vertex_count(), system.pinned_vertex_indices()),
      settings_(settings) {}

FrameRecord LevelStepper::step(Eigen::VectorXd& x, int frame,
                               const NewtonSolver::Progress& progress) {
  return step(x, frame, system_.scene().time.step, progress);
}

FrameRecord LevelStepper::step(Eigen::VectorXd& x, int frame, double time_step,
                               const NewtonSolver::Progress& progress) {
  const Eigen::VectorXd previous = x;
  return step(previous, x, frame, time_step, 0, progress);
}

FrameRecord LevelStepper::step(const Eigen::VectorXd& previous, Eigen::VectorXd& x, int frame,
                               double time_step, int iterations_done,
                               const NewtonSolver::Progress& progress) {
  objective_->set_time_step(time_step);
  objective_->set_previous(previous);
  FrameRecord record;
  record.frame = frame;
  record.time = frame * system_.scene().time.step;
  NewtonSettings settings = settings_;
  settings.max_iterations -= iterations_done;
  record.newton = solve_pinned_step(newton_, *objective_, system_, dofs_, settings, frame, x,
                                    offset_progress(progress, iterations_done));
  record.newton.iterations += iterations_done;
  record.elastic_energy = objective_->elastic_energy(x);
  return record;
}

}  // namespace psq
