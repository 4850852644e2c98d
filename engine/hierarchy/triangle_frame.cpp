#include "engine/hierarchy/triangle_frame.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace psq {

namespace {

/// σ₂/σ₁ below which a deformed triangle counts as rank-deficient.
constexpr double kRankTolerance = 1e-12;
/// Smallest divisor used anywhere, so that a fully collapsed triangle stays finite.
constexpr double kTinyDivisor = 1e-300;

Eigen::Vector3d any_unit_orthogonal(const Eigen::Vector3d& u) {
  // Cross with the axis least aligned with u: never parallel to it.
  Eigen::Index axis = 0;
  u.cwiseAbs().minCoeff(&axis);
  return u.cross(Eigen::Vector3d::Unit(axis)).normalized();
}

}  // namespace

bool rest_triangle_frame(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                         const Eigen::Vector3d& x2, RestTriangleFrame& frame) {
  const Eigen::Vector3d edge1 = x1 - x0;
  const Eigen::Vector3d edge2 = x2 - x0;
  const Eigen::Vector3d cross = edge1.cross(edge2);
  const double length1 = edge1.norm();
  const double double_area = cross.norm();
  if (!(double_area > 0) || !std::isfinite(double_area)) return false;
  frame.e1 = edge1 / length1;
  frame.normal = cross / double_area;
  frame.e2 = frame.normal.cross(frame.e1);
  Eigen::Matrix2d b;
  b << length1, edge1.dot(edge2) / length1, 0, double_area / length1;
  frame.b_inverse = b.inverse();
  return true;
}

DeformedTriangleFrame deformed_triangle_frame(const Eigen::Vector3d& x0,
                                              const Eigen::Vector3d& x1,
                                              const Eigen::Vector3d& x2,
                                              const Eigen::Matrix2d& b_inverse) {
  DeformedTriangleFrame frame;
  frame.edge1 = x1 - x0;
  frame.edge2 = x2 - x0;
  Matrix32d f;
  f << frame.edge1, frame.edge2;
  f = f * b_inverse;

  // Closed-form eigen-decomposition of S = FᵀF = [[a, b], [b, c]]. σ₂ comes from
  // σ₁σ₂ = |f₁×f₂| = |e₁×e₂|·det B⁻¹, which has no cancellation when F is nearly singular.
  const double a = f.col(0).squaredNorm();
  const double b = f.col(0).dot(f.col(1));
  const double c = f.col(1).squaredNorm();
  const double sigma1 = std::sqrt(0.5 * (a + c) + std::hypot(0.5 * (a - c), b));
  const Eigen::Vector3d cross = frame.edge1.cross(frame.edge2);
  const double cross_length = cross.norm();
  const double sigma2 = sigma1 > 0 ? cross_length * b_inverse.determinant() / sigma1 : 0.0;
  const double angle = 0.5 * std::atan2(2 * b, a - c);
  const Eigen::Vector2d v1(std::cos(angle), std::sin(angle));
  const Eigen::Vector2d v2(-v1.y(), v1.x());

  const Eigen::Vector3d u1 = sigma1 > 0 ? Eigen::Vector3d(f * v1 / sigma1)
                                        : Eigen::Vector3d::UnitX();
  const bool full_rank = sigma2 > kRankTolerance * sigma1;
  frame.normal = full_rank ? Eigen::Vector3d(cross / cross_length) : any_unit_orthogonal(u1);
  // det V = +1 and F = U Σ Vᵀ with u₂ = n × u₁, so R = u₁v₁ᵀ + u₂v₂ᵀ has r₁ × r₂ = n.
  const Eigen::Vector3d u2 = frame.normal.cross(u1);
  frame.rotation = u1 * v1.transpose() + u2 * v2.transpose();

  const double sigma2_floor = std::max({sigma2, kRankTolerance * sigma1, kRankTolerance});
  const double sigma1_floor = std::max(sigma1, kRankTolerance);
  frame.stretch_inverse = v1 * v1.transpose() / sigma1_floor + v2 * v2.transpose() / sigma2_floor;
  frame.stretch_trace = sigma1_floor + sigma2_floor;
  const double edge_scale = frame.edge1.squaredNorm() + frame.edge2.squaredNorm();
  frame.normal_length = std::max({cross_length, kRankTolerance * edge_scale, kTinyDivisor});
  return frame;
}

Eigen::Matrix3d offset_gradient(const DeformedTriangleFrame& frame,
                                const Eigen::Matrix2d& b_inverse, const Eigen::Vector3d& q,
                                const Matrix32d& k) {
  const Eigen::Vector3d& n = frame.normal;
  const Matrix32d& r = frame.rotation;
  Matrix32d r_j;  // R J with J = [[0, −1], [1, 0]]
  r_j << r.col(1), -r.col(0);
  const double beta = r_j.cwiseProduct(k).sum();
  const Eigen::Vector2d s = k.transpose() * n;
  const Matrix32d grad_f =
      (beta / frame.stretch_trace) * r_j + n * (frame.stretch_inverse * s).transpose();
  const Matrix32d grad_edges = grad_f * b_inverse.transpose();

  const Eigen::Vector3d h = (q - n * n.dot(q)) / frame.normal_length;
  Eigen::Matrix3d gradient;
  gradient.col(1) = grad_edges.col(0) + frame.edge2.cross(h);
  gradient.col(2) = grad_edges.col(1) + h.cross(frame.edge1);
  gradient.col(0) = -gradient.col(1) - gradient.col(2);
  return gradient;
}

}  // namespace psq
