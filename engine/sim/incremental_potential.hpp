#pragma once
// The quasistatic incremental potential of one pseudo time step (DESIGN.md §4):
//   E(x) = 1/(2Δt²)‖x − xᵗ‖²_M + Σ Ψ_membrane(x) + Σ Ψ_bending(x) − f·x.

#include "engine/sim/shell_system.hpp"
#include "engine/solver/objective.hpp"

namespace psq {

class IncrementalPotential : public Objective {
 public:
  IncrementalPotential(const ShellSystem& system, double time_step);

  /// The previous step's positions xᵗ, the centre of the inertia-like term.
  void set_previous(const Eigen::VectorXd& previous) { previous_ = previous; }

  [[nodiscard]] Eigen::Index size() const override { return previous_.size(); }
  double value(const Eigen::VectorXd& x) override;
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override;
  void hessian(const Eigen::VectorXd& x, HessianBlocks& H) override;

  /// Elastic energy alone (membrane plus bending), for reports.
  [[nodiscard]] double elastic_energy(const Eigen::VectorXd& x) const;

 private:
  const ShellSystem& system_;
  double inertia_weight_;  ///< 1/Δt²
  Eigen::VectorXd previous_;
};

}  // namespace psq
