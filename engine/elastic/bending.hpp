#pragma once
// Discrete hinge bending with rest dihedral angles (DESIGN.md §4), per interior edge:
//   W = k (θ − θ̄)² · 3|ē|² / (Ā₀ + Ā₁),
// θ the signed dihedral angle (engine/elastic/dihedral_angle.hpp), θ̄ its value on the rest
// mesh (curved rest shapes keep their shape), ē and Ā_i the rest edge and face areas.
// k = D/6 with D = E h³/(12(1 − ν²)): derived in docs/bending-calibration.md so that the
// isometric wrap of a flat regular mesh onto a cylinder of radius R has energy (D/2)·A/R².

#include <Eigen/Core>
#include <vector>

#include "engine/core/element_matrices.hpp"
#include "engine/elastic/dihedral_angle.hpp"
#include "engine/elastic/material.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Rest data of one hinge.
struct HingeRest {
  double angle;   ///< θ̄
  double weight;  ///< 3|ē|²/(Ā₀ + Ā₁)
};

/// The hinge constant k = D/6 = E h³/(72 (1 − ν²)) (docs/bending-calibration.md).
double bending_stiffness(const Material& material);

/// Rest angle and weight of a hinge that is not degenerate (is_degenerate_hinge).
HingeRest hinge_rest(const HingePositions& rest);

/// θ − θ̄ wrapped into [−π, π], so W stays continuous when a fold passes through ±π.
double hinge_angle_deviation(const HingePositions& x, const HingeRest& rest);

/// W = k·w·(θ − θ̄)²; +∞ for a degenerate hinge (θ undefined), so line searches reject it.
double hinge_energy(const HingePositions& x, const HingeRest& rest, double stiffness);

/// ∇W = 2 k w (θ − θ̄) ∇θ. Throws NumericalError for a degenerate hinge.
HingeVector hinge_gradient(const HingePositions& x, const HingeRest& rest, double stiffness);

/// ∇²W = 2 k w [∇θ ∇θᵀ + (θ − θ̄) ∇²θ]. With project_psd, the Gauss–Newton term
/// 2 k w ∇θ ∇θᵀ alone: PSD by construction, exact at θ = θ̄. It replaces the eigen-projection
/// of the full block because it is ~15× cheaper (a 9×9 eigensolve was 5 µs per hinge, 80% of
/// the assembly at 50k vertices) and converged in fewer Newton iterations on the example
/// scenes (drape 199 vs 203, twist 581 vs 676 iterations over 25 frames).
/// Throws NumericalError for a degenerate hinge.
HingeMatrix hinge_hessian(const HingePositions& x, const HingeRest& rest, double stiffness,
                          bool project_psd);

/// The bending energy of one shell inside a scene's global position vector x (size 3N):
/// the shell's local vertex i is global vertex vertex_offset + i.
class BendingEnergy {
 public:
  /// Precomputes every hinge's rest angle and weight. Throws InputError for a hinge whose
  /// rest edge or faces are degenerate.
  BendingEnergy(const TriMesh& rest, const MeshTopology& topology, const Material& material,
                int vertex_offset = 0);

  /// Σ over hinges; +∞ if any hinge is degenerate. Throws NumericalError for non-finite
  /// positions.
  [[nodiscard]] double value(const Eigen::VectorXd& x) const;
  /// g += ∇W(x). Throws NumericalError for non-finite positions or a degenerate hinge.
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// One 12×12 block per hinge (stencil: global v0, v1, opposite0, opposite1), PSD-projected
  /// unless project_psd is false. Reuses out's storage when its stencils already match.
  void hessian(const Eigen::VectorXd& x, ElementMatrices& out, bool project_psd = true) const;

  /// The calibrated hinge constant k.
  [[nodiscard]] double stiffness() const { return stiffness_; }
  [[nodiscard]] int hinge_count() const { return static_cast<int>(rest_.size()); }

 private:
  void check(const Eigen::VectorXd& x) const;

  double stiffness_;
  int vertex_offset_;
  int vertex_count_;
  std::vector<int> stencils_;  ///< 4 global vertices per hinge
  std::vector<HingeRest> rest_;
};

}  // namespace psq
