#pragma once
// The interface every minimized energy implements: value, gradient, projected Hessian
// blocks and a feasible step bound (the CCD-safe step once contact exists).

#include <Eigen/Core>
#include <vector>

#include "engine/core/element_matrices.hpp"

namespace psq {

/// A PSD-projected Hessian in element form: a diagonal (mass-like terms) plus batches of
/// dense element blocks. The sparse assembler sums them over the free degrees of freedom.
struct HessianBlocks {
  Eigen::VectorXd diagonal;             ///< size 3n
  std::vector<ElementMatrices> batches; ///< reused between iterations; stencils may change
  /// Set by the solver before it asks: per vertex, whether the solve holds it (empty: none).
  /// Its rows never reach the system, so a term may project only the block of the vertices
  /// that move (project_moving_block_to_psd).
  std::vector<bool> fixed_vertices;
  /// Set by the solver before it asks: false asks for ∇²E itself, its element blocks not
  /// projected (NewtonSettings::project_on_demand), so near a minimum Newton sees the curvature
  /// the projection would overstate. An objective without such blocks may answer with its PSD
  /// approximation.
  bool project = true;
};

class Objective {
 public:
  virtual ~Objective() = default;
  /// Number of unknowns (3 × vertices).
  [[nodiscard]] virtual Eigen::Index size() const = 0;
  virtual double value(const Eigen::VectorXd& x) = 0;
  /// Overwrites g (resized to size()) with ∇E(x).
  virtual void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) = 0;
  /// Overwrites H with a positive semi-definite approximation of ∇²E(x), or with ∇²E(x) where
  /// it can when H.project is false.
  virtual void hessian(const Eigen::VectorXd& x, HessianBlocks& H) = 0;
  /// Largest α in (0, 1] such that x + α·dx stays feasible (intersection-free, within
  /// strain limits). Unconstrained objectives return 1.
  virtual double max_feasible_step(const Eigen::VectorXd& /*x*/, const Eigen::VectorXd& /*dx*/) {
    return 1.0;
  }
};

}  // namespace psq
