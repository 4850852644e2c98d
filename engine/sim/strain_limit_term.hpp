#pragma once
// C-IPC strain limiting as a term of the incremental potential: one StrainLimitEnergy per shell
// whose material sets `strain_limit` (docs/friction-and-strain-limiting.md). The line search
// never leaves the feasible set (max_feasible_step); κ_s of each shell starts at the scene's
// value or E h δ² and doubles between Newton chunks while the barrier loses against the other
// forces (update_stiffness).

#include <map>
#include <string>
#include <vector>

#include "engine/elastic/strain_limit.hpp"
#include "engine/sim/potential_term.hpp"
#include "engine/sim/shell_system.hpp"

namespace psq {

/// Whether any shell of the scene sets a strain limit.
bool strain_limit_enabled(const Scene& scene);

class StrainLimitTerm : public PotentialTerm {
 public:
  /// The barrier of every limited shell of `system` (band (1, strain_limit)).
  explicit StrainLimitTerm(const ShellSystem& system);

  /// Throws InputError naming the shell, its largest stretch and its limit unless every
  /// triangle of x is strictly below its shell's limit. `state` says which state x is ("the
  /// rest state", "the restored state") for the message.
  void require_feasible(const Eigen::VectorXd& x, const std::string& state) const;

  /// Codim-IPC's κ_s update of each limited shell at the iterate x
  /// (update_strain_limit_stiffness, against that shell's slack at the previous call); true when
  /// any κ_s changed.
  bool update_stiffness(const Eigen::VectorXd& x);

  /// Adds each limited shell's κ_s and last slack to `state` ("strain_limit.<shell>.*").
  void save_state(std::map<std::string, double>& state) const;
  /// Takes back what save_state wrote; names missing from `state` keep their values.
  void load_state(const std::map<std::string, double>& state);

  /// The limited shells' energies, in scene order of the shells.
  [[nodiscard]] const std::vector<StrainLimitEnergy>& energies() const { return energies_; }

  double value(const Eigen::VectorXd& x) override;
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override;
  void hessian(const Eigen::VectorXd& x, const std::vector<bool>& fixed_vertices,
               bool project_psd, Eigen::VectorXd& diagonal, ElementMatrices& blocks) override;
  /// 1 when no limited shell's triangle reaches its limit along x + α dx, α ∈ [0, 1]; else
  /// 0.9 × the smallest StrainLimitEnergy::max_feasible_step, so that each triangle keeps at
  /// least a tenth of its slack.
  double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) override;

 private:
  /// What update_stiffness keeps per limited shell.
  struct Adaptation {
    std::string shell;          ///< the shell's name, for messages
    double max_stiffness;       ///< κ_s never doubles beyond this
    double previous_min_slack;  ///< s̄ − σ₁ of the tightest triangle at the last update
  };

  std::vector<StrainLimitEnergy> energies_;
  std::vector<Adaptation> adaptations_;
  ElementMatrices shell_blocks_;  ///< one shell's blocks, gathered into the term's
};

}  // namespace psq
