#include "engine/progressive/level_stepper.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/core/error.hpp"

namespace psq {

LevelStepper::LevelStepper(const ShellSystem& system, std::unique_ptr<LevelObjective> objective,
                           const NewtonSettings& settings)
    : system_(system),
      objective_(std::move(objective)),
      dofs_(system.rest_mesh().vertex_count(), system.pinned_vertex_indices()),
      settings_(settings) {}

double settling_time_step(double time_step, int settle_step) {
  return time_step * std::pow(4.0, std::min(settle_step, kSettlingGrowthSteps));
}

bool settling_done(int settle_step, double change, double tolerance) {
  return settle_step >= kSettlingGrowthSteps && change < tolerance;
}

void DirectObjective::set_time_step(double time_step) {
  if (time_step == time_step_) return;
  potential_.emplace(system_, time_step);  // xᵗ is reset to the rest state: set it afterwards
  time_step_ = time_step;
}

FrameRecord LevelStepper::step(Eigen::VectorXd& x, int frame,
                               const NewtonSolver::Progress& progress) {
  return step(x, frame, system_.scene().time.step, progress);
}

FrameRecord LevelStepper::step(Eigen::VectorXd& x, int frame, double time_step,
                               const NewtonSolver::Progress& progress) {
  objective_->set_time_step(time_step);
  FrameRecord record;
  record.frame = frame;
  record.time = frame * system_.scene().time.step;
  objective_->set_previous(x);
  system_.apply_pins(x, record.time);
  if (!std::isfinite(objective_->value(x)))
    throw NumericalError(fmt::format(
        "frame {}: moving the pinned vertices to their scripted positions inverts or degenerates "
        "triangles next to them; use more frames (smaller steps of the motion)", frame));
  record.newton = newton_.minimize(*objective_, x, dofs_, settings_, progress);
  record.elastic_energy = objective_->elastic_energy(x);
  return record;
}

}  // namespace psq
