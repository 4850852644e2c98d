#pragma once
// The coarse-level proxy of the fine incremental potential (paper eqs. 2–3, §4.5):
//   F(x_l) = 1/(2Δt²)‖x_l − x_lᵗ‖²_{M_l} + Ψ_L(P^l(x_l)) − f_L·P^l(x_l) + C_l(x_l),
// fine-scale elastics Ψ_L and external force f_L evaluated through the direct prolongation P^l,
// level-l masses M_l, and C_l the level's own contact, friction and strain-limit terms (added to
// its incremental potential like at the finest level). Newton-type steps use the exact gradient
// or the paper's eq.-10 gradient with the offsets held, and level l's own projected Hessian as
// preconditioner,
//   H(x_l) = M_l/Δt² + PSD(∇²E_membrane,l(x_l)) + s_l·PSD(∇²E_bending,l(x_l)),
// its bending part scaled by s_l, about how much stiffer the fine bending through P^l is
// (√(fine / level triangles), the coarse/fine edge-length ratio): without it the steps
// overshoot and the line search backtracks.

#include "engine/progressive/level_objective.hpp"
#include "engine/progressive/system_prolongation.hpp"
#include "engine/sim/elastic_model.hpp"
#include "engine/sim/shell_system.hpp"

#include <optional>
#include <vector>

namespace psq {

/// Which gradient ProxyElastics::add_gradient adds.
enum class ProxyGradient {
  /// Uᵀ(∇Ψ_L − f_L)(P(x)): the prolongation's offsets held at their current value (paper
  /// eq. 10). Not the gradient of F: the line search sees F itself.
  held_offsets,
  /// (∂P/∂x)ᵀ(∇Ψ_L − f_L)(P(x)): the gradient of F.
  exact,
};

/// Ψ_L(P^l(x)) − f_L·P^l(x) with the level's scaled Hessian blocks.
class ProxyElastics : public ElasticModel {
 public:
  /// `level`: the level's system (elastics for the preconditioner); `finest`: the finest system
  /// (elastics and external force of the proxy); `to_finest`: P^l. All three are referenced.
  ProxyElastics(const ShellSystem& level, const ShellSystem& finest,
                const SystemProlongation& to_finest, ProxyGradient gradient);

  /// Ψ_L(P^l(x)).
  [[nodiscard]] double elastic_energy(const Eigen::VectorXd& x) const override;
  [[nodiscard]] double energy(const Eigen::VectorXd& x) const override;
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const override;
  void hessian(const Eigen::VectorXd& x, std::vector<ElementMatrices>& batches,
               bool project_psd) const override;

 private:
  /// What the proxy knows at one coarse x, independent of xᵗ and Δt. Filled lazily and
  /// remembered for the last x: a step's report asks for the elastic energy of its final point,
  /// which the line search has just evaluated, and a step that does not move the pins
  /// (settling) starts where the last one ended. The gradient is not kept: it is seldom asked
  /// twice at one x.
  struct FineEvaluation {
    Eigen::VectorXd x;              ///< the key, compared bitwise
    Eigen::VectorXd prolonged;      ///< P^l(x)
    std::optional<double> elastic;  ///< Ψ_L(P^l(x))
  };
  /// The evaluation at x, reset (with P^l(x) computed) when x differs from the remembered one.
  /// A non-finite x, which apply() rejects, is never remembered.
  [[nodiscard]] FineEvaluation& at(const Eigen::VectorXd& x) const;
  [[nodiscard]] double elastic_at(FineEvaluation& fine) const;

  const ShellSystem& level_;
  const ShellSystem& finest_;
  const SystemProlongation& to_finest_;
  std::vector<double> bending_scale_;  ///< s_l per shell
  ProxyGradient gradient_kind_;
  mutable FineEvaluation memo_;  // mutable so that the const evaluations share it
};

/// F(x_l): the level's incremental potential with ProxyElastics as its elastic part.
class ProxyObjective : public LevelObjective {
 public:
  ProxyObjective(const ShellSystem& level, const ShellSystem& finest,
                 const SystemProlongation& to_finest, double time_step, ProxyGradient gradient)
      : LevelObjective(level, time_step,
                       std::make_unique<ProxyElastics>(level, finest, to_finest, gradient)) {}
};

}  // namespace psq
