#pragma once
// The quasistatic incremental potential of one pseudo time step (DESIGN.md §4):
//   E(x) = 1/(2Δt²)‖x − xᵗ‖²_M + Σ Ψ_membrane(x) + Σ Ψ_bending(x) − f·x + Σ_terms T(x),
// where the added terms (PotentialTerm) are the contact barrier, friction, the strain-limit
// barrier and the kinematic pull of scripted vertices. Ψ − f·x is the system's own unless an
// ElasticModel replaces it (a progressive level's fine elastics through the prolongation).

#include <vector>

#include "engine/sim/elastic_model.hpp"
#include "engine/sim/potential_term.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/solver/objective.hpp"

namespace psq {

class IncrementalPotential : public Objective {
 public:
  /// `elastics`: Ψ − f·x and its Hessian blocks, referenced (it must outlive the potential);
  /// null for the system's own shells.
  IncrementalPotential(const ShellSystem& system, double time_step,
                       const ElasticModel* elastics = nullptr);

  /// The previous step's positions xᵗ, the centre of the inertia-like term.
  void set_previous(const Eigen::VectorXd& previous) { previous_ = previous; }
  /// The pseudo time step Δt of the inertia-like term (settling steps grow it).
  void set_time_step(double time_step) { inertia_weight_ = 1.0 / (time_step * time_step); }
  /// 1/Δt², the weight of the inertia-like term.
  [[nodiscard]] double inertia_weight() const { return inertia_weight_; }

  /// Adds a term to the sum. The potential does not own it: the term must outlive the potential
  /// or be removed first.
  void add_term(PotentialTerm& term);
  void remove_term(const PotentialTerm& term);

  [[nodiscard]] Eigen::Index size() const override { return previous_.size(); }
  double value(const Eigen::VectorXd& x) override;
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override;
  /// Batches: the elastic model's (membrane and bending per shell), then one per added term.
  void hessian(const Eigen::VectorXd& x, HessianBlocks& H) override;
  /// The smallest feasible step of the added terms (1 without terms).
  double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) override;

  /// ∇ of everything but the inertia-like term: the static potential's gradient, whose entries
  /// at pinned DOFs are the forces holding them (engine/sim/probes.hpp).
  void static_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g);
  /// ∇ of the inertia, elastic and external parts alone, without the added terms.
  void base_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// Elastic energy alone (membrane plus bending, or the model's Ψ), for reports.
  [[nodiscard]] double elastic_energy(const Eigen::VectorXd& x) const;

 private:
  const ShellSystem& system_;
  const ElasticModel* elastics_;  ///< null: the system's own shells
  double inertia_weight_;         ///< 1/Δt²
  Eigen::VectorXd previous_;
  std::vector<PotentialTerm*> terms_;
};

}  // namespace psq
