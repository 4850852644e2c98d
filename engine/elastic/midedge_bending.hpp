#pragma once
// Mid-edge (discrete shape operator) bending, per triangle, from the dihedral angles of its
// three edges. Derivation and measurements: docs/midedge-bending.md.
//
// Mid-edge normals: across edge i (opposite corner p_i) the normal at the edge midpoint is the
// face normal turned towards the edge by φ_i; interpolated linearly between the three edge
// midpoints it gives the face a constant second fundamental form II, and the Kirchhoff–Love
// energy W = Ā·D/2·[ν tr(M)² + (1 − ν) tr(M²)], M = ā⁻¹ (II − ĪI), D = E h³/(12 (1 − ν²)).
// The dihedral angle θ_i fixes only the sum of the turns on its two sides; how it is split
// (MidedgeSplit) is the whole model. Either way, with δθ = θ − θ̄ (θ̄ from the rest shape),
//   W = ½ δθᵀ S δθ,  S a constant 3×3 per face (rows and columns of boundary edges zero).
// A boundary edge has no angle and adds nothing (docs/midedge-bending.md, "Boundary edges").

#include <Eigen/Core>
#include <array>
#include <vector>

#include "engine/core/element_matrices.hpp"
#include "engine/elastic/dihedral_angle.hpp"
#include "engine/elastic/material.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// Positions of a mid-edge element as columns: the face's corners p0, p1, p2, then q0, q1, q2,
/// q_i the vertex across edge i (the edge p_{i+1}p_{i+2} opposite p_i). Column 3 + i is not
/// read when edge i is on the boundary.
using MidedgePositions = Eigen::Matrix<double, 3, 6>;
using MidedgeVector = Eigen::Matrix<double, 18, 1>;
using MidedgeMatrix = Eigen::Matrix<double, 18, 18>;

/// The face and its neighbours in the face's rest plane: columns p0, p1, p2, q0, q1, q2 in an
/// orthonormal frame of the face (p0 at the origin, p1 on the first axis), each q_i unfolded
/// about its edge onto the far side (distances to the edge's ends kept). Columns of boundary
/// edges are not read.
using MidedgePatch = Eigen::Matrix<double, 2, 6>;

/// How a dihedral angle is shared between the mid-edge normals of its two faces.
enum class MidedgeSplit {
  /// Half each (averaged mid-edge normals, Grinspun et al. 2006, the small-strain "theta"
  /// form of libshell's averaged formulation):
  ///   S_ij = D |ē_i||ē_j| / (4 Ā) · [ν + (1 − ν)(ê_i·ê_j)²].
  /// Exact only where neighbouring faces mirror each other: the cylinder wrap of a grid along its
  /// axes, and consistent under load there (cantilever within 2–4%), but 13% too stiff on a
  /// Delaunay sheet and up to 64% on a turned grid.
  halves,
  /// From the patch: II is the constant curvature of the face and its neighbours (unfolded into
  /// the face's rest plane) whose angles are the measured ones, θ = C β (midedge_angle_map), the
  /// least-energy one when a boundary edge leaves it free (Phaal & Calladine 1992, in dihedral
  /// angles): S = (C Q⁻¹ Cᵀ)⁻¹ over the interior edges. Exact for every constant curvature on
  /// any mesh, but on the checkerboard grid a twist alternating from cell row to cell row
  /// couples to bending: a loaded cantilever is 1.5× too soft.
  patch_fit,
};

/// Rest data of one face.
struct MidedgeRest {
  Eigen::Matrix3d stiffness;  ///< S of W = ½ δθᵀ S δθ; rows and columns of boundary edges 0
  Eigen::Vector3d angle;      ///< θ̄_i (0 on boundary edges)
  std::array<bool, 3> interior;  ///< edge i has a neighbouring face
};

/// The rest patch of a face whose interior hinges are not degenerate.
MidedgePatch unfolded_patch(const MidedgePositions& rest, const std::array<bool, 3>& interior);

/// C: row i gives the dihedral angle θ_i = c_iᵀ β of edge i on the patch bent to the height
/// field z = ½ vᵀ II v along the face normal, β = (II₁₁, II₂₂, II₁₂), to first order: with
/// II(v) = vᵀ II v and a, b the edge's ends,
///   θ_i = −½ (d_i(p_i)/h_i(p_i) + d_i(q_i)/h_i(q_i)),  d_i(r) = ½ (II(r − a) + II(r − b) − II(b −
///   a)),
/// h_i(r) the distance of r from the edge's line (the jump of the slopes of the two triangles'
/// linear interpolants of a quadratic height field, docs/midedge-bending.md). Rows of boundary
/// edges are zero.
Eigen::Matrix3d midedge_angle_map(const MidedgePatch& patch, const std::array<bool, 3>& interior);

/// Q of W = ½ βᵀ Q β for a constant curvature β = (II₁₁, II₂₂, II₁₂) over a rest area Ā:
/// Ā D [ν t tᵀ + (1 − ν) diag(1, 1, 2)], t = (1, 1, 0).
Eigen::Matrix3d curvature_energy_matrix(double area, const Material& material);

/// S of MidedgeSplit::halves for a rest triangle (columns p0, p1, p2; ē_i = p_{i+2} − p_{i+1}):
/// the energy Ā·D/2·[ν tr(M)² + (1 − ν) tr(M²)] of II = Σ_i h̄_i δθ_i ∇λ_i∇λ_iᵀ, rows and
/// columns of boundary edges zero.
Eigen::Matrix3d averaged_normal_stiffness(const Eigen::Matrix3d& rest_triangle,
                                          const std::array<bool, 3>& interior,
                                          const Material& material);

/// S of MidedgeSplit::patch_fit. Throws NumericalError when no constant curvature fits the
/// patch's angles (the six vertices on a conic, C singular).
Eigen::Matrix3d patch_fit_stiffness(const MidedgePositions& rest,
                                    const std::array<bool, 3>& interior, const Material& material);

/// Rest data of a face whose triangle and interior hinges are not degenerate.
MidedgeRest midedge_rest(const MidedgePositions& rest, const std::array<bool, 3>& interior,
                         const Material& material, MidedgeSplit split = MidedgeSplit::halves);

/// The hinge of edge i as dihedral_angle sees it: (p_{i+1}, p_{i+2}, p_i, q_i), so that the face
/// is the hinge's face 0 in its own orientation.
HingePositions midedge_hinge(const MidedgePositions& x, int edge);

/// True when an interior edge's hinge is degenerate (is_degenerate_hinge); the face is face 0
/// of each of them.
bool is_degenerate_midedge(const MidedgePositions& x, const MidedgeRest& rest);

/// δθ_i = θ_i − θ̄_i wrapped into [−π, π] (a fold through ±π stays continuous); 0 on boundary
/// edges.
Eigen::Vector3d midedge_angle_change(const MidedgePositions& x, const MidedgeRest& rest);

/// W = ½ δθᵀ S δθ; +∞ for a degenerate face or hinge, so line searches reject it.
double midedge_energy(const MidedgePositions& x, const MidedgeRest& rest);

/// ∇W = Σ_i (S δθ)_i ∇θ_i. Throws NumericalError when degenerate.
MidedgeVector midedge_gradient(const MidedgePositions& x, const MidedgeRest& rest);

/// ∇²W = Jᵀ S J + Σ_i (S δθ)_i ∇²θ_i, J the 3×18 Jacobian of θ. With project_psd, the
/// Gauss–Newton term Jᵀ S J alone: PSD because S is, and exact at rest, as for the hinges
/// (engine/elastic/bending.hpp). Throws NumericalError when degenerate.
MidedgeMatrix midedge_hessian(const MidedgePositions& x, const MidedgeRest& rest, bool project_psd);

/// The mid-edge bending energy of one shell inside a scene's global position vector x (size
/// 3N): the shell's local vertex i is global vertex vertex_offset + i. One element per face
/// with at least one interior edge.
class MidedgeBendingEnergy {
 public:
  /// Precomputes every face's stiffness and rest angles. Throws InputError for a rest face or
  /// hinge that is degenerate, or a patch that no constant curvature fits.
  MidedgeBendingEnergy(const TriMesh& rest, const MeshTopology& topology, const Material& material,
                       int vertex_offset = 0, MidedgeSplit split = MidedgeSplit::halves);

  /// Σ over faces; +∞ if any face is degenerate. Throws NumericalError for non-finite positions.
  [[nodiscard]] double value(const Eigen::VectorXd& x) const;
  /// g += ∇W(x). Throws NumericalError for non-finite positions or a degenerate face.
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// One 18×18 block per face (stencil: global p0, p1, p2, q0, q1, q2; a boundary edge's q_i
  /// repeats p_i with a zero block), Gauss–Newton unless project_psd is false. Reuses out's
  /// storage when its stencils already match.
  void hessian(const Eigen::VectorXd& x, ElementMatrices& out, bool project_psd = true) const;

  [[nodiscard]] int element_count() const { return static_cast<int>(rest_.size()); }

 private:
  void check(const Eigen::VectorXd& x) const;

  int vertex_offset_;
  int vertex_count_;
  std::vector<int> stencils_;  ///< 6 global vertices per element
  std::vector<MidedgeRest> rest_;
};

}  // namespace psq
