#pragma once
// Reference solutions for progressive runs: direct quasistatic stepping of one system with its
// own elastics, run over the scene's frames and then settled at the last frame, the same
// equilibrium criterion the progressive solver uses at its refine frame.

#include <Eigen/Core>
#include <functional>

#include "engine/progressive/level_stepper.hpp"
#include "engine/progressive/progressive_simulation.hpp"

namespace psq::test {

struct DirectRun {
  Eigen::VectorXd positions;
  int newton_iterations = 0;
  bool settled = false;  ///< the last settling step changed x by less than the tolerance
};

/// Frames 1..frames of `system` (its own elastics, masses and gravity), each solved to
/// `tolerance` (‖d‖∞/Δt), then settling steps at the last frame (settling_time_step,
/// settling_done: the progressive solver's rule), at most `max_settle_steps` of them.
inline DirectRun settled_direct_run(const ShellSystem& system, double tolerance,
                                    int max_settle_steps = 200) {
  const Scene& scene = system.scene();
  NewtonSettings newton;
  newton.step_scale = scene.time.step;
  newton.tolerance = tolerance;
  newton.max_iterations = scene.solver.max_iterations;
  newton.project_on_demand = scene.solver.project_on_demand;
  LevelStepper stepper(system, std::make_unique<LevelObjective>(system, scene.time.step), newton);
  DirectRun run;
  run.positions = flat(system.rest_mesh().vertices);
  for (int frame = 1; frame <= scene.time.frames; ++frame)
    run.newton_iterations += stepper.step(run.positions, frame).newton.iterations;
  for (int k = 0; k < max_settle_steps && !run.settled; ++k) {
    const Eigen::VectorXd before = run.positions;
    run.newton_iterations +=
        stepper.step(run.positions, scene.time.frames, settling_time_step(scene.time.step, k))
            .newton.iterations;
    run.settled = settling_done(
        k, (run.positions - before).lpNorm<Eigen::Infinity>() / scene.time.step, tolerance);
  }
  return run;
}

/// Runs the schedule of `sim` from its current state to its end, calling `check` (when given)
/// after every step and every refinement.
inline void run_to_end(ProgressiveSimulation& sim, const std::function<void()>& check = {}) {
  for (;;) {
    while (!sim.level_done()) {
      sim.step();
      if (check) check();
    }
    if (sim.finished()) return;
    sim.refine();
    if (check) check();
  }
}

/// Largest distance between corresponding vertices of two flat position vectors.
inline double max_vertex_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd d = a - b;
  double worst = 0.0;
  for (Eigen::Index v = 0; v < d.size() / 3; ++v)
    worst = std::max(worst, d.segment<3>(3 * v).norm());
  return worst;
}

/// The root mean square of the per-vertex distances between flat positions a and b.
inline double rms_vertex_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::sqrt((a - b).squaredNorm() / double(a.size() / 3));
}

}  // namespace psq::test
