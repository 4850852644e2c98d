#pragma once
// The objective of one quasistatic step at one level of a progressive solve: an incremental
// potential centred at the previous step's positions xᵗ.

#include "engine/sim/incremental_potential.hpp"
#include "engine/solver/objective.hpp"

namespace psq {

class LevelObjective : public Objective {
 public:
  /// The previous step's positions xᵗ (this level's vertices), the centre of the inertia term.
  virtual void set_previous(const Eigen::VectorXd& previous) = 0;
  /// The pseudo time step Δt of the inertia-like term 1/(2Δt²)‖x − xᵗ‖²_M.
  virtual void set_time_step(double time_step) = 0;
  /// The elastic energy the objective minimizes, at the finest scale, for reports.
  [[nodiscard]] virtual double elastic_energy(const Eigen::VectorXd& x) const = 0;
};

/// The true incremental potential of a system (eq. 1): the finest level of a progressive solve,
/// or a direct simulation of any level with its own elastics. Delegates to IncrementalPotential,
/// so a one-level progressive solve takes exactly the steps of QuasistaticSimulation.
class DirectObjective : public LevelObjective {
 public:
  DirectObjective(const ShellSystem& system, double time_step)
      : potential_(system, time_step) {}

  void set_previous(const Eigen::VectorXd& previous) override {
    potential_.set_previous(previous);
  }
  void set_time_step(double time_step) override { potential_.set_time_step(time_step); }
  [[nodiscard]] double elastic_energy(const Eigen::VectorXd& x) const override {
    return potential_.elastic_energy(x);
  }
  [[nodiscard]] Eigen::Index size() const override { return potential_.size(); }
  double value(const Eigen::VectorXd& x) override { return potential_.value(x); }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    potential_.gradient(x, g);
  }
  void hessian(const Eigen::VectorXd& x, HessianBlocks& H) override { potential_.hessian(x, H); }

 private:
  IncrementalPotential potential_;
};

}  // namespace psq
