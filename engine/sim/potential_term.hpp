#pragma once
// A further term of the incremental potential (DESIGN.md §4: barrier, friction, strain limit,
// kinematic targets). IncrementalPotential sums its terms into value, gradient, Hessian and the
// feasible step, so a new physical effect is one class implementing this interface.

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "engine/core/element_matrices.hpp"

namespace psq {

/// Sets `value` to state[name] when `state` has it (terms restoring their adaptive state).
inline void load_named(const std::map<std::string, double>& state, const std::string& name,
                       double& value) {
  if (const auto found = state.find(name); found != state.end()) value = found->second;
}

class PotentialTerm {
 public:
  virtual ~PotentialTerm() = default;
  virtual double value(const Eigen::VectorXd& x) = 0;
  /// g += ∇(term)(x).
  virtual void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) = 0;
  /// A PSD approximation of the term's Hessian over the vertices the solve moves (those not in
  /// `fixed_vertices`, HessianBlocks), or the Hessian itself where the term projects blocks
  /// and `project_psd` is false (HessianBlocks::project): entries added to `diagonal` (size 3n)
  /// and/or element blocks written to `blocks` (which the term resets, possibly to no element).
  virtual void hessian(const Eigen::VectorXd& x, const std::vector<bool>& fixed_vertices,
                       bool project_psd, Eigen::VectorXd& diagonal, ElementMatrices& blocks) = 0;
  /// Largest α ∈ (0, 1] keeping x + α·dx feasible for this term; 1 when unconstrained.
  virtual double max_feasible_step(const Eigen::VectorXd& /*x*/, const Eigen::VectorXd& /*dx*/) {
    return 1.0;
  }
};

}  // namespace psq
