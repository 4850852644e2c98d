#include "engine/sim/quasistatic.hpp"

#include <fmt/format.h>

#include "engine/core/error.hpp"

namespace psq {

QuasistaticSimulation::QuasistaticSimulation(const Scene& scene)
    : system_(scene),
      potential_(system_, scene.time.step),
      dofs_(system_.rest_mesh().vertex_count(), system_.pinned_vertex_indices()),
      x_(flat(system_.rest_mesh().vertices)) {
  settings_.step_scale = scene.time.step;
  settings_.max_iterations = scene.solver.max_iterations;
  settings_.tolerance = scene.solver.tolerance.value_or(
      1e-4 * bounding_box_diagonal(system_.rest_mesh().vertices));
}

FrameRecord QuasistaticSimulation::step(const Progress& progress) {
  FrameRecord record;
  record.frame = frame_ + 1;
  record.time = record.frame * system_.scene().time.step;
  potential_.set_previous(x_);
  Eigen::VectorXd x = x_;
  system_.apply_pins(x, record.time);
  if (!std::isfinite(potential_.value(x)))
    throw NumericalError(fmt::format(
        "frame {}: moving the pinned vertices to their scripted positions inverts or degenerates "
        "triangles next to them; use more frames (smaller steps of the motion)", record.frame));
  const int frame_number = record.frame;
  record.newton = newton_.minimize(potential_, x, dofs_, settings_, [&](const NewtonIteration& it) {
    if (progress) progress(frame_number, it);
  });
  x_ = std::move(x);
  frame_ = record.frame;
  record.elastic_energy = potential_.elastic_energy(x_);
  return record;
}

}  // namespace psq
