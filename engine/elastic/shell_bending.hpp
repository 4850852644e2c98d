#pragma once
// The bending energy of one shell in whichever model its scene chose, behind one interface, so
// that the sums of elastic energy (incremental potential, progressive proxy, reports) do not
// branch on the model.

#include <Eigen/Core>
#include <variant>

#include "engine/core/element_matrices.hpp"
#include "engine/elastic/bending.hpp"
#include "engine/elastic/bending_model.hpp"
#include "engine/elastic/material.hpp"
#include "engine/elastic/midedge_bending.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Hinge or mid-edge bending of one shell inside a scene's global position vector x (size 3N):
/// the shell's local vertex i is global vertex vertex_offset + i.
class ShellBending {
 public:
  /// Builds `model`'s rest data. Throws InputError for a degenerate rest mesh, as the chosen
  /// energy's constructor does.
  ShellBending(BendingModel model, const TriMesh& rest, const MeshTopology& topology,
               const Material& material, int vertex_offset = 0);

  /// The total bending energy; +∞ if an element is degenerate. Throws NumericalError for
  /// non-finite positions.
  [[nodiscard]] double value(const Eigen::VectorXd& x) const;
  /// g += ∇W(x). Throws NumericalError for non-finite positions or a degenerate element.
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// One block per element (12×12 per hinge, 18×18 per mid-edge face), PSD unless
  /// project_psd is false. Reuses out's storage when its stencils already match.
  void hessian(const Eigen::VectorXd& x, ElementMatrices& out, bool project_psd = true) const;

  [[nodiscard]] BendingModel model() const;

 private:
  std::variant<BendingEnergy, MidedgeBendingEnergy> energy_;
};

}  // namespace psq
