#pragma once
// Quasistatic stepping of a scene at one resolution: each frame moves the pinned vertices to
// their scripted positions and minimizes the incremental potential with Newton.

#include <functional>

#include "engine/sim/incremental_potential.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/solver/newton.hpp"

namespace psq {

/// One solved frame.
struct FrameRecord {
  int frame = 0;            ///< 1-based; frame 0 is the rest state
  double time = 0.0;        ///< frame · Δt
  double elastic_energy = 0.0;
  NewtonResult newton;
};

class QuasistaticSimulation {
 public:
  /// Called for every Newton iteration of a frame (frame number, record).
  using Progress = std::function<void(int frame, const NewtonIteration&)>;

  /// Builds the shell system of `scene` and starts at its rest state.
  explicit QuasistaticSimulation(const Scene& scene);

  [[nodiscard]] const ShellSystem& system() const { return system_; }
  [[nodiscard]] const Eigen::VectorXd& positions() const { return x_; }
  [[nodiscard]] int frame() const { return frame_; }
  [[nodiscard]] int frame_count() const { return system_.scene().time.frames; }
  [[nodiscard]] const NewtonSettings& newton_settings() const { return settings_; }

  /// Solves the next frame. A frame that does not converge within the iteration limit is
  /// returned with newton.converged = false; numerical failures throw NumericalError.
  FrameRecord step(const Progress& progress = {});

 private:
  ShellSystem system_;
  IncrementalPotential potential_;
  DofMap dofs_;
  NewtonSolver newton_;
  NewtonSettings settings_;
  Eigen::VectorXd x_;
  int frame_ = 0;
};

}  // namespace psq
