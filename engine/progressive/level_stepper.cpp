#include "engine/progressive/level_stepper.hpp"

#include <algorithm>

namespace psq {

LevelStepper::LevelStepper(const ShellSystem& system, std::unique_ptr<LevelObjective> objective,
                           const NewtonSettings& settings)
    : system_(system),
      objective_(std::move(objective)),
      frame_solver_(system, objective_->potential()),
      settings_(settings) {}

FrameRecord LevelStepper::step(Eigen::VectorXd& x, int frame,
                               const NewtonSolver::Progress& progress) {
  return step(x, frame, system_.scene().time.step, progress);
}

FrameRecord LevelStepper::step(Eigen::VectorXd& x, int frame, double time_step,
                               const NewtonSolver::Progress& progress) {
  const Eigen::VectorXd previous = x;
  return step(previous, x, frame, time_step, 0, settings_, progress);
}

FrameRecord LevelStepper::step(const Eigen::VectorXd& previous, Eigen::VectorXd& x, int frame,
                               double time_step, int iterations_done,
                               const NewtonSettings& step_settings,
                               const NewtonSolver::Progress& progress,
                               const Eigen::VectorXd& frame_start) {
  objective_->set_time_step(time_step);
  objective_->set_previous(previous);
  FrameRecord record;
  record.frame = frame;
  record.time = frame * system_.scene().time.step;
  NewtonSettings settings = step_settings;
  settings.max_iterations -= iterations_done;
  int taken = iterations_done;
  const NewtonSolver::Progress numbered = numbered_through_frame(progress, taken);
  // A settling step's targets are where the pins already are: begin_frame then only raises κ to
  // the balance at x, if that is higher. The scripted vertices' way is solved with the scene's
  // budget and judged even in a preview: a pull stopped after a preview's few iterations would
  // be followed by stiffer pulls that crush the gaps, or leave the preview behind its script.
  NewtonSettings scripted = settings;
  scripted.max_iterations =
      std::max(settings.max_iterations, system_.scene().solver.max_iterations - iterations_done);
  scripted.judge_final_iterate = true;
  frame_solver_.begin_frame(x, record, scripted, numbered);
  settings.max_iterations = std::max(0, settings.max_iterations - record.newton.iterations);
  frame_solver_.solve_held(x, previous, frame_start.size() > 0 ? frame_start : previous, record,
                           settings, numbered);
  frame_solver_.finish_frame(x, record);
  record.newton.iterations += iterations_done;
  record.elastic_energy = objective_->elastic_energy(x);
  return record;
}

}  // namespace psq
