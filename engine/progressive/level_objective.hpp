#pragma once
// The objective of one quasistatic step at one level of a progressive solve: the incremental
// potential centred at the previous step's positions xᵗ, with the level's elastic model (the
// system's own shells at the finest level, the fine elastics through the prolongation below,
// proxy_objective.hpp) and the contact, friction and strain-limit terms its frame solver adds.
// With the system's own shells it is the true incremental potential (eq. 1), so a one-level
// progressive solve takes exactly the steps of QuasistaticSimulation.

#include <memory>

#include "engine/sim/elastic_model.hpp"
#include "engine/sim/incremental_potential.hpp"
#include "engine/solver/objective.hpp"

namespace psq {

class LevelObjective : public Objective {
 public:
  /// `system` is referenced; `elastics` replaces the system's own Ψ − f·x when not null.
  LevelObjective(const ShellSystem& system, double time_step,
                 std::unique_ptr<ElasticModel> elastics = nullptr)
      : elastics_(std::move(elastics)), potential_(system, time_step, elastics_.get()) {}

  /// The incremental potential itself, to which the level's frame solver adds its terms.
  [[nodiscard]] IncrementalPotential& potential() { return potential_; }

  /// The previous step's positions xᵗ (this level's vertices), the centre of the inertia term.
  void set_previous(const Eigen::VectorXd& previous) { potential_.set_previous(previous); }
  /// The pseudo time step Δt of the inertia-like term 1/(2Δt²)‖x − xᵗ‖²_M.
  void set_time_step(double time_step) { potential_.set_time_step(time_step); }
  /// The elastic energy the objective minimizes, at the finest scale, for reports.
  [[nodiscard]] double elastic_energy(const Eigen::VectorXd& x) const {
    return potential_.elastic_energy(x);
  }
  [[nodiscard]] Eigen::Index size() const override { return potential_.size(); }
  double value(const Eigen::VectorXd& x) override { return potential_.value(x); }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    potential_.gradient(x, g);
  }
  void hessian(const Eigen::VectorXd& x, HessianBlocks& H) override { potential_.hessian(x, H); }
  double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) override {
    return potential_.max_feasible_step(x, dx);
  }

 private:
  std::unique_ptr<ElasticModel> elastics_;  // before potential_, which refers to it
  IncrementalPotential potential_;
};

}  // namespace psq
