#include "engine/elastic/membrane.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "engine/core/error.hpp"
#include "engine/elastic/element_loop.hpp"

namespace psq {
namespace {

/// det(FᵀF) = |f1 × f2|², exact to rounding even for nearly collinear columns.
double gram_determinant(const DeformationGradient& F) {
  return F.col(0).cross(F.col(1)).squaredNorm();
}

void require_regular(const DeformationGradient& F) {
  if (!(gram_determinant(F) > 0))
    throw NumericalError("membrane: degenerate triangle (J = 0), derivatives undefined");
}

}  // namespace

double membrane_density(const DeformationGradient& F, const PlaneStressLame& lame) {
  const double det = gram_determinant(F);
  if (!(det > 0)) return std::numeric_limits<double>::infinity();
  const double log_j = 0.5 * std::log(det);
  return 0.5 * lame.mu * (F.squaredNorm() - 2.0) - lame.mu * log_j +
         0.5 * lame.lambda * log_j * log_j;
}

DeformationGradient membrane_stress(const DeformationGradient& F, const PlaneStressLame& lame) {
  require_regular(F);
  const Eigen::Matrix2d gram = F.transpose() * F;
  const double log_j = 0.5 * std::log(gram_determinant(F));
  return lame.mu * F + (lame.lambda * log_j - lame.mu) * F * gram.inverse();
}

DeformationGradientMatrix membrane_stress_derivative(const DeformationGradient& F,
                                                     const PlaneStressLame& lame,
                                                     bool project_psd) {
  require_regular(F);
  const double det = gram_determinant(F);
  // Singular vectors from the 2×2 eigenproblem of FᵀF in closed form.
  const Eigen::Matrix2d gram = F.transpose() * F;
  const double half_gap = std::hypot(0.5 * (gram(0, 0) - gram(1, 1)), gram(0, 1));
  const double largest = 0.5 * gram.trace() + half_gap;
  const double s1 = std::sqrt(largest);
  const double s2 = std::sqrt(det / largest);  // not trace/2 − gap: no cancellation
  const double phi = 0.5 * std::atan2(2.0 * gram(0, 1), gram(0, 0) - gram(1, 1));
  const Eigen::Vector2d v1(std::cos(phi), std::sin(phi));
  const Eigen::Vector2d v2(-v1.y(), v1.x());
  const Eigen::Vector3d u1 = F * v1 / s1;
  const Eigen::Vector3d n = F.col(0).cross(F.col(1)).normalized();
  const Eigen::Vector3d u2 = n.cross(u1);  // stable even when s2 ≪ s1

  const double mu = lame.mu;
  const double lambda = lame.lambda;
  const double c = lambda * std::log(s1 * s2) - mu;
  DeformationGradientMatrix h = DeformationGradientMatrix::Zero();
  const auto add_mode = [&](double eigenvalue, const DeformationGradientVector& mode) {
    if (project_psd && eigenvalue < 0) return;
    h.noalias() += eigenvalue * mode * mode.transpose();
  };

  Eigen::Matrix2d scaling;
  scaling << mu + (lambda - c) / (s1 * s1), lambda / (s1 * s2), lambda / (s1 * s2),
      mu + (lambda - c) / (s2 * s2);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> scaling_modes;
  scaling_modes.computeDirect(scaling);
  for (int m = 0; m < 2; ++m) {
    const Eigen::Vector2d w = scaling_modes.eigenvectors().col(m);
    add_mode(scaling_modes.eigenvalues()[m], w[0] * vec_outer(u1, v1) + w[1] * vec_outer(u2, v2));
  }
  const double inv_sqrt2 = 1.0 / std::sqrt(2.0);
  add_mode(mu + c / (s1 * s2), inv_sqrt2 * (vec_outer(u1, v2) - vec_outer(u2, v1)));
  add_mode(mu - c / (s1 * s2), inv_sqrt2 * (vec_outer(u1, v2) + vec_outer(u2, v1)));
  add_mode(mu + c / (s1 * s1), vec_outer(n, v1));
  add_mode(mu + c / (s2 * s2), vec_outer(n, v2));
  return h;
}

double membrane_triangle_energy(const TrianglePositions& x, const MembraneRest& rest,
                                const PlaneStressLame& lame, double thickness) {
  return thickness * rest.area * membrane_density(deformation_gradient(x, rest), lame);
}

TriangleVector membrane_triangle_gradient(const TrianglePositions& x, const MembraneRest& rest,
                                          const PlaneStressLame& lame, double thickness) {
  return pull_back_stress(membrane_stress(deformation_gradient(x, rest), lame), rest,
                          thickness * rest.area);
}

TriangleMatrix membrane_triangle_hessian(const TrianglePositions& x, const MembraneRest& rest,
                                         const PlaneStressLame& lame, double thickness,
                                         bool project_psd) {
  return pull_back_stress_derivative(
      membrane_stress_derivative(deformation_gradient(x, rest), lame, project_psd), rest,
      thickness * rest.area);
}

MembraneEnergy::MembraneEnergy(const TriMesh& rest, const Material& material, int vertex_offset)
    : lame_(plane_stress_lame(material)),
      thickness_(material.thickness),
      vertex_offset_(vertex_offset),
      vertex_count_(rest.vertex_count()),
      triangles_(rest, vertex_offset, "membrane") {}

void MembraneEnergy::check(const Eigen::VectorXd& x) const {
  check_positions(x, vertex_offset_, vertex_count_, "membrane");
}

double MembraneEnergy::value(const Eigen::VectorXd& x) const {
  check(x);
  return parallel_element_sum(triangles_.size(), [&](std::size_t t) {
    return membrane_triangle_energy(triangles_.positions(x, t), triangles_.rest(t), lame_,
                                    thickness_);
  });
}

void MembraneEnergy::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  check(x);
  add_element_gradients<3>(
      triangles_.stencils(),
      [&](std::size_t t) {
        return membrane_triangle_gradient(triangles_.positions(x, t), triangles_.rest(t), lame_,
                                          thickness_);
      },
      g);
}

void MembraneEnergy::hessian(const Eigen::VectorXd& x, ElementMatrices& out,
                             bool project_psd) const {
  check(x);
  fill_element_hessians<3>(
      triangles_.stencils(),
      [&](std::size_t t) {
        return membrane_triangle_hessian(triangles_.positions(x, t), triangles_.rest(t), lame_,
                                         thickness_, project_psd);
      },
      out);
}

}  // namespace psq
