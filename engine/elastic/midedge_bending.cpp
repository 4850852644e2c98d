#include "engine/elastic/midedge_bending.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "engine/core/error.hpp"
#include "engine/elastic/element_loop.hpp"
#include "engine/elastic/lame.hpp"

namespace psq {
namespace {

/// Where the hinge of edge i (x0..x3 of midedge_hinge) sits among the element's six vertices.
std::array<int, 4> hinge_slots(int edge) {
  return {(edge + 1) % 3, (edge + 2) % 3, edge, 3 + edge};
}

/// Below this ratio of the extreme eigenvalues of C Q⁻¹ Cᵀ no constant curvature explains some
/// combination of the patch's angles; its stiffness would be unbounded.
constexpr double kSingularPatch = 1e-10;

/// The coefficients of β = (II₁₁, II₂₂, II₁₂) in II(v) = vᵀ II v.
Eigen::RowVector3d quadratic_form_row(const Eigen::Vector2d& v) {
  return {v.x() * v.x(), v.y() * v.y(), 2.0 * v.x() * v.y()};
}

/// d(r)/h(r) of the triangle (a, b, r) as a row acting on β: the slope of its linear
/// interpolant of z = ½ II(v), relative to the true slope at the edge, across the edge ab.
Eigen::RowVector3d slope_jump_row(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                  const Eigen::Vector2d& r) {
  const Eigen::Vector2d edge = b - a;
  const Eigen::Vector2d ra = r - a;
  const double height = std::abs(edge.x() * ra.y() - edge.y() * ra.x()) / edge.norm();
  return 0.5 * (quadratic_form_row(ra) + quadratic_form_row(r - b) - quadratic_form_row(edge)) /
         height;
}

void scatter_edge_gradient(const HingeVector& g, int edge, MidedgeVector& out) {
  const std::array<int, 4> slots = hinge_slots(edge);
  for (int a = 0; a < 4; ++a) out.segment<3>(3 * slots[a]) += g.segment<3>(3 * a);
}

void scatter_edge_hessian(const HingeMatrix& h, int edge, MidedgeMatrix& out) {
  const std::array<int, 4> slots = hinge_slots(edge);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      out.block<3, 3>(3 * slots[a], 3 * slots[b]) += h.block<3, 3>(3 * a, 3 * b);
}

void require_regular(const MidedgePositions& x, const MidedgeRest& rest) {
  if (is_degenerate_midedge(x, rest))
    throw NumericalError("mid-edge bending: degenerate face or hinge, derivatives undefined");
}

/// δθ and its Jacobian (3×18; rows of boundary edges zero).
struct AngleChange {
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 18> jacobian = Eigen::Matrix<double, 3, 18>::Zero();
};

AngleChange angle_change_with_jacobian(const MidedgePositions& x, const MidedgeRest& rest) {
  require_regular(x, rest);
  AngleChange change;
  change.value = midedge_angle_change(x, rest);
  for (int i = 0; i < 3; ++i) {
    if (!rest.interior[i]) continue;
    MidedgeVector row = MidedgeVector::Zero();
    scatter_edge_gradient(dihedral_angle_gradient(midedge_hinge(x, i)), i, row);
    change.jacobian.row(i) = row.transpose();
  }
  return change;
}

}  // namespace

MidedgePatch unfolded_patch(const MidedgePositions& rest, const std::array<bool, 3>& interior) {
  const Eigen::Vector3d e1 = rest.col(1) - rest.col(0);
  const Eigen::Vector3d axis_x = e1.normalized();
  const Eigen::Vector3d normal = e1.cross(rest.col(2) - rest.col(0)).normalized();
  const Eigen::Vector3d axis_y = normal.cross(axis_x);
  MidedgePatch patch = MidedgePatch::Zero();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d r = rest.col(k) - rest.col(0);
    patch.col(k) << r.dot(axis_x), r.dot(axis_y);
  }
  for (int i = 0; i < 3; ++i) {
    if (!interior[i]) continue;
    // q_i keeps its foot point on the edge and its distance from it, on the far side of p_i.
    const Eigen::Vector3d a = rest.col((i + 1) % 3), b = rest.col((i + 2) % 3);
    const Eigen::Vector3d edge = b - a;
    const double along = (rest.col(3 + i) - a).dot(edge) / edge.squaredNorm();
    const double distance = (rest.col(3 + i) - a - along * edge).norm();
    const Eigen::Vector2d a2 = patch.col((i + 1) % 3), edge2 = patch.col((i + 2) % 3) - a2;
    Eigen::Vector2d away(edge2.y(), -edge2.x());
    away.normalize();
    if (away.dot(patch.col(i) - a2) > 0) away = -away;
    patch.col(3 + i) = a2 + along * edge2 + distance * away;
  }
  return patch;
}

Eigen::Matrix3d midedge_angle_map(const MidedgePatch& patch, const std::array<bool, 3>& interior) {
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (!interior[i]) continue;
    const Eigen::Vector2d a = patch.col((i + 1) % 3), b = patch.col((i + 2) % 3);
    c.row(i) = -0.5 * (slope_jump_row(a, b, patch.col(i)) + slope_jump_row(a, b, patch.col(3 + i)));
  }
  return c;
}

Eigen::Matrix3d curvature_energy_matrix(double area, const Material& material) {
  const double nu = material.poisson_ratio;
  const Eigen::Vector3d trace(1.0, 1.0, 0.0);
  const Eigen::Matrix3d squares = Eigen::Vector3d(1.0, 1.0, 2.0).asDiagonal();
  return area * bending_modulus(material) * (nu * trace * trace.transpose() + (1.0 - nu) * squares);
}

Eigen::Matrix3d averaged_normal_stiffness(const Eigen::Matrix3d& rest_triangle,
                                          const std::array<bool, 3>& interior,
                                          const Material& material) {
  // With d_i = h̄_i δθ_i, h̄_i = 2Ā/|ē_i| and ∇λ_i·∇λ_j = ē_i·ē_j/(4Ā²), the density becomes
  // D/(16 Ā³) h̄_i h̄_j [ν |ē_i|²|ē_j|² + (1 − ν)(ē_i·ē_j)²] (docs/midedge-bending.md).
  Eigen::Matrix3d edges;
  for (int i = 0; i < 3; ++i)
    edges.col(i) = rest_triangle.col((i + 2) % 3) - rest_triangle.col((i + 1) % 3);
  const double area = 0.5 * edges.col(1).cross(edges.col(2)).norm();
  const double nu = material.poisson_ratio;
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (!interior[i] || !interior[j]) continue;
      const double lengths = edges.col(i).norm() * edges.col(j).norm();
      const double cosine = edges.col(i).dot(edges.col(j)) / lengths;
      s(i, j) =
          bending_modulus(material) * lengths / (4.0 * area) * (nu + (1.0 - nu) * cosine * cosine);
    }
  return s;
}

Eigen::Matrix3d patch_fit_stiffness(const MidedgePositions& rest,
                                    const std::array<bool, 3>& interior, const Material& material) {
  const double area = 0.5 * (rest.col(1) - rest.col(0)).cross(rest.col(2) - rest.col(0)).norm();
  const Eigen::Matrix3d c = midedge_angle_map(unfolded_patch(rest, interior), interior);
  const Eigen::Matrix3d compliance = curvature_energy_matrix(area, material).inverse();

  // S = (C Q⁻¹ Cᵀ)⁻¹ on the interior edges only: the least energy of a constant curvature
  // that produces given angles there, whatever it does across the boundary edges.
  std::vector<int> edges;
  for (int i = 0; i < 3; ++i)
    if (interior[i]) edges.push_back(i);
  const int m = static_cast<int>(edges.size());
  Eigen::MatrixXd c_interior(m, 3);
  for (int k = 0; k < m; ++k) c_interior.row(k) = c.row(edges[k]);
  const Eigen::MatrixXd angle_compliance = c_interior * compliance * c_interior.transpose();
  const Eigen::VectorXd eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(angle_compliance, Eigen::EigenvaluesOnly)
          .eigenvalues();
  if (m == 0 || !(eigenvalues.minCoeff() > kSingularPatch * eigenvalues.maxCoeff()))
    throw NumericalError(
        "mid-edge bending: no constant curvature fits the rest patch's angles (its six "
        "vertices lie on a conic)");
  const Eigen::MatrixXd interior_stiffness =
      angle_compliance.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (int k = 0; k < m; ++k)
    for (int l = 0; l < m; ++l)
      s(edges[k], edges[l]) = 0.5 * (interior_stiffness(k, l) + interior_stiffness(l, k));
  return s;
}

MidedgeRest midedge_rest(const MidedgePositions& rest, const std::array<bool, 3>& interior,
                         const Material& material, MidedgeSplit split) {
  MidedgeRest r{split == MidedgeSplit::halves
                    ? averaged_normal_stiffness(rest.leftCols<3>(), interior, material)
                    : patch_fit_stiffness(rest, interior, material),
                Eigen::Vector3d::Zero(), interior};
  for (int i = 0; i < 3; ++i)
    if (interior[i]) r.angle[i] = dihedral_angle(midedge_hinge(rest, i));
  return r;
}

HingePositions midedge_hinge(const MidedgePositions& x, int edge) {
  HingePositions hinge;
  const std::array<int, 4> slots = hinge_slots(edge);
  for (int a = 0; a < 4; ++a) hinge.col(a) = x.col(slots[a]);
  return hinge;
}

bool is_degenerate_midedge(const MidedgePositions& x, const MidedgeRest& rest) {
  for (int i = 0; i < 3; ++i)
    if (rest.interior[i] && is_degenerate_hinge(midedge_hinge(x, i))) return true;
  return false;
}

Eigen::Vector3d midedge_angle_change(const MidedgePositions& x, const MidedgeRest& rest) {
  Eigen::Vector3d change = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    if (rest.interior[i])
      change[i] = angle_difference(dihedral_angle(midedge_hinge(x, i)), rest.angle[i]);
  return change;
}

double midedge_energy(const MidedgePositions& x, const MidedgeRest& rest) {
  if (is_degenerate_midedge(x, rest)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d change = midedge_angle_change(x, rest);
  return 0.5 * change.dot(rest.stiffness * change);
}

MidedgeVector midedge_gradient(const MidedgePositions& x, const MidedgeRest& rest) {
  const AngleChange change = angle_change_with_jacobian(x, rest);
  return change.jacobian.transpose() * (rest.stiffness * change.value);
}

MidedgeMatrix midedge_hessian(const MidedgePositions& x, const MidedgeRest& rest,
                              bool project_psd) {
  const AngleChange change = angle_change_with_jacobian(x, rest);
  MidedgeMatrix h = change.jacobian.transpose() * rest.stiffness * change.jacobian;
  if (project_psd) return h;
  const Eigen::Vector3d moment = rest.stiffness * change.value;
  for (int i = 0; i < 3; ++i)
    if (rest.interior[i])
      scatter_edge_hessian(moment[i] * dihedral_angle_hessian(midedge_hinge(x, i)), i, h);
  return h;
}

MidedgeBendingEnergy::MidedgeBendingEnergy(const TriMesh& rest, const MeshTopology& topology,
                                           const Material& material, int vertex_offset,
                                           MidedgeSplit split)
    : vertex_offset_(vertex_offset), vertex_count_(rest.vertex_count()) {
  for (int f = 0; f < rest.triangle_count(); ++f) {
    int stencil[6];
    std::array<bool, 3> interior{};
    for (int i = 0; i < 3; ++i) {
      stencil[i] = rest.triangles(f, i);
      const int edge = topology.face_edges[f][i];
      const auto [face_a, face_b] = topology.edge_faces[edge];
      const int neighbour = face_a == f ? face_b : face_a;
      interior[i] = neighbour >= 0;
      // A boundary edge's slot repeats p_i: its rows of every block are zero.
      stencil[3 + i] = stencil[i];
      if (!interior[i]) continue;
      for (int k = 0; k < 3; ++k) {
        const int v = rest.triangles(neighbour, k);
        if (v != topology.edges[edge][0] && v != topology.edges[edge][1]) stencil[3 + i] = v;
      }
    }
    if (!interior[0] && !interior[1] && !interior[2]) continue;  // an isolated triangle
    MidedgePositions corners;
    for (int a = 0; a < 6; ++a) corners.col(a) = rest.vertices.row(stencil[a]).transpose();
    if (is_degenerate_midedge(corners,
                              {Eigen::Matrix3d::Zero(), Eigen::Vector3d::Zero(), interior}))
      throw InputError(fmt::format(
          "mid-edge bending: rest face {} or one of its neighbours is degenerate (zero-length "
          "edge or zero-area triangle)",
          f));
    try {
      rest_.push_back(midedge_rest(corners, interior, material, split));
    } catch (const NumericalError& e) {
      throw InputError(fmt::format("{} (rest face {}); perturb the mesh", e.what(), f));
    }
    for (int a = 0; a < 6; ++a) stencils_.push_back(vertex_offset + stencil[a]);
  }
}

void MidedgeBendingEnergy::check(const Eigen::VectorXd& x) const {
  check_positions(x, vertex_offset_, vertex_count_, "mid-edge bending");
}

double MidedgeBendingEnergy::value(const Eigen::VectorXd& x) const {
  check(x);
  return parallel_element_sum(rest_.size(), [&](std::size_t e) {
    return midedge_energy(element_positions<6>(x, stencils_, e), rest_[e]);
  });
}

void MidedgeBendingEnergy::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  check(x);
  add_element_gradients<6>(
      stencils_,
      [&](std::size_t e) {
        return midedge_gradient(element_positions<6>(x, stencils_, e), rest_[e]);
      },
      g);
}

void MidedgeBendingEnergy::hessian(const Eigen::VectorXd& x, ElementMatrices& out,
                                   bool project_psd) const {
  check(x);
  fill_element_hessians<6>(
      stencils_,
      [&](std::size_t e) {
        return midedge_hessian(element_positions<6>(x, stencils_, e), rest_[e], project_psd);
      },
      out);
}

}  // namespace psq
