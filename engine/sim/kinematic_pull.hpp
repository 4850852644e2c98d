#pragma once
// How scripted vertices (pinned shell sets, collider vertices) reach their targets safely when
// contact is on. Moving them directly could push a collider through a shell, so when the CCD
// says the direct move is not safe, they become unknowns pulled toward their targets by
//   P(x) = ½ k Σᵢ Σ_c wᵢ_c (xᵢ_c − yᵢ_c)²,   wᵢ_c = max(mᵢ/Δt², E h/(1 − ν²)),
// over the components c a pin fixes (wᵢ_c = 0 on a free component, which the pull leaves free),
// and the solver's CCD line search keeps every iterate intersection-free (IPC's treatment of
// kinematic boundary conditions, with a penalty of growing stiffness k in place of the
// augmented Lagrangian's multipliers). IPC weighs by mass alone, which suits dynamics; in a
// quasistatic solve the inertia is tiny beside the elastic forces, and a plate pulled that
// softly against a stiff can lags far behind its target for several rounds, each a full
// solve. The floor E h/(1 − ν²), the stiffest shell's membrane stiffness, makes the pull as
// firm as the structure it presses. Once the rest of the way is safe they are pinned at the
// targets; see FrameSolver.

#include <vector>

#include "engine/sim/potential_term.hpp"

namespace psq {

class KinematicPull : public PotentialTerm {
 public:
  /// The vertices to pull, their targets (3 per vertex, in a vector of 3n like x) and weights,
  /// one per component (0 for a component the pull leaves alone).
  void set(std::vector<int> vertices, const Eigen::VectorXd& targets,
           std::vector<Eigen::Vector3d> weights);
  void set_stiffness(double k) { stiffness_ = k; }
  [[nodiscard]] double stiffness() const { return stiffness_; }
  [[nodiscard]] const std::vector<int>& vertices() const { return vertices_; }

  double value(const Eigen::VectorXd& x) override;
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override;
  /// Diagonal only: k wᵢ_c on the DOFs of each pulled vertex.
  void hessian(const Eigen::VectorXd& x, const std::vector<bool>& fixed_vertices,
               bool project_psd, Eigen::VectorXd& diagonal, ElementMatrices& blocks) override;

 private:
  std::vector<int> vertices_;
  Eigen::VectorXd targets_;
  std::vector<Eigen::Vector3d> weights_;
  double stiffness_ = 1.0;
};

}  // namespace psq
