#include "engine/elastic/dihedral_angle.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "engine/core/error.hpp"

namespace psq {
namespace {

/// Everything the derivative formulas share, measured from x0.
struct HingeFrame {
  Eigen::Vector3d e, b0, b1;  ///< x1 − x0, x2 − x0, x3 − x0
  Eigen::Vector3d n0, n1;     ///< e × b0 and b1 × e; |n_i| = twice the face area
  double e_norm, n0_sq, n1_sq;
};

HingeFrame hinge_frame(const HingePositions& x) {
  HingeFrame f;
  f.e = x.col(1) - x.col(0);
  f.b0 = x.col(2) - x.col(0);
  f.b1 = x.col(3) - x.col(0);
  f.n0 = f.e.cross(f.b0);
  f.n1 = f.b1.cross(f.e);
  f.e_norm = f.e.norm();
  f.n0_sq = f.n0.squaredNorm();
  f.n1_sq = f.n1.squaredNorm();
  return f;
}

/// Below this sine of a face's angle at x0 the face normal is rounding noise. No usable mesh
/// comes near it; a collapsed face does.
constexpr double kDegenerateSine = 1e-12;

bool is_degenerate(const HingeFrame& f) {
  const double limit0 = kDegenerateSine * f.e_norm * f.b0.norm();
  const double limit1 = kDegenerateSine * f.e_norm * f.b1.norm();
  return !(f.e_norm > 0 && f.n0_sq > limit0 * limit0 && f.n1_sq > limit1 * limit1);
}

void require_regular(const HingeFrame& f) {
  if (is_degenerate(f))
    throw NumericalError("dihedral angle: degenerate hinge (zero-length edge or collapsed face)");
}

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// d(n/|n|²)/dn = (I − 2 n̂ n̂ᵀ)/|n|².
Eigen::Matrix3d scaled_normal_derivative(const Eigen::Vector3d& n, double n_sq) {
  return (Eigen::Matrix3d::Identity() - 2.0 * n * n.transpose() / n_sq) / n_sq;
}

/// ∂θ/∂x1, ∂θ/∂x2, ∂θ/∂x3 (the x0 part follows from translation invariance), plus the foot
/// parameters α0, α1 they are built from.
struct RelativeGradient {
  Eigen::Vector3d g1, g2, g3;
  double alpha0, alpha1;
};

RelativeGradient relative_gradient(const HingeFrame& f) {
  RelativeGradient r;
  const double e_sq = f.e_norm * f.e_norm;
  r.alpha0 = f.b0.dot(f.e) / e_sq;
  r.alpha1 = f.b1.dot(f.e) / e_sq;
  r.g2 = -f.e_norm / f.n0_sq * f.n0;
  r.g3 = -f.e_norm / f.n1_sq * f.n1;
  r.g1 = -r.alpha0 * r.g2 - r.alpha1 * r.g3;
  return r;
}

double angle(const HingeFrame& f) {
  // Both atan2 arguments carry the factor |n0||n1||e|, so no normalization is needed and a
  // degenerate hinge gives atan2(0, 0) = 0 instead of NaN.
  return std::atan2(f.e.dot(f.n0.cross(f.n1)), f.e_norm * f.n0.dot(f.n1));
}

HingeVector gradient(const HingeFrame& f) {
  require_regular(f);
  const RelativeGradient r = relative_gradient(f);
  HingeVector g;
  g << -(r.g1 + r.g2 + r.g3), r.g1, r.g2, r.g3;
  return g;
}

}  // namespace

double dihedral_angle(const HingePositions& x) { return angle(hinge_frame(x)); }

std::optional<double> regular_dihedral_angle(const HingePositions& x) {
  const HingeFrame f = hinge_frame(x);
  if (is_degenerate(f)) return std::nullopt;
  return angle(f);
}

bool is_degenerate_hinge(const HingePositions& x) { return is_degenerate(hinge_frame(x)); }

HingeVector dihedral_angle_gradient(const HingePositions& x) { return gradient(hinge_frame(x)); }

DihedralAngleAndGradient dihedral_angle_and_gradient(const HingePositions& x) {
  const HingeFrame f = hinge_frame(x);
  return {angle(f), gradient(f)};
}

HingeRelativeMatrix dihedral_angle_relative_hessian(const HingePositions& x) {
  const HingeFrame f = hinge_frame(x);
  require_regular(f);
  const RelativeGradient r = relative_gradient(f);
  const double e_sq = f.e_norm * f.e_norm;
  const Eigen::Vector3d e_hat = f.e / f.e_norm;
  const Eigen::Matrix3d e_cross = cross_matrix(f.e);
  const Eigen::Matrix3d q0 = scaled_normal_derivative(f.n0, f.n0_sq);
  const Eigen::Matrix3d q1 = scaled_normal_derivative(f.n1, f.n1_sq);
  const Eigen::Matrix3d zero = Eigen::Matrix3d::Zero();

  // g2 = −|e| n0/|n0|² with dn0 = −[b0]× dx1 + [e]× dx2; g3 = −|e| n1/|n1|² with
  // dn1 = [b1]× dx1 − [e]× dx3; d|e| = ê·dx1.
  const Eigen::Matrix3d dg2[3] = {
      -f.n0 / f.n0_sq * e_hat.transpose() + f.e_norm * q0 * cross_matrix(f.b0),
      -f.e_norm * q0 * e_cross, zero};
  const Eigen::Matrix3d dg3[3] = {
      -f.n1 / f.n1_sq * e_hat.transpose() - f.e_norm * q1 * cross_matrix(f.b1), zero,
      f.e_norm * q1 * e_cross};
  // α_i = b_i·e/|e|².
  const Eigen::Vector3d dalpha0[3] = {(f.b0 - 2.0 * r.alpha0 * f.e) / e_sq, f.e / e_sq,
                                      Eigen::Vector3d::Zero()};
  const Eigen::Vector3d dalpha1[3] = {(f.b1 - 2.0 * r.alpha1 * f.e) / e_sq, Eigen::Vector3d::Zero(),
                                      f.e / e_sq};

  HingeRelativeMatrix h;
  for (int j = 0; j < 3; ++j) {
    // g1 = −α0 g2 − α1 g3.
    h.block<3, 3>(0, 3 * j) = -r.g2 * dalpha0[j].transpose() - r.alpha0 * dg2[j] -
                              r.g3 * dalpha1[j].transpose() - r.alpha1 * dg3[j];
    h.block<3, 3>(3, 3 * j) = dg2[j];
    h.block<3, 3>(6, 3 * j) = dg3[j];
  }
  // The exact Hessian is symmetric; average away the rounding in the two triangles.
  return 0.5 * (h + h.transpose());
}

HingeMatrix dihedral_angle_hessian(const HingePositions& x) {
  return expand_translation_invariant(dihedral_angle_relative_hessian(x));
}

HingeMatrix expand_translation_invariant(const HingeRelativeMatrix& relative) {
  HingeMatrix h;
  h.bottomRightCorner<9, 9>() = relative;
  for (int j = 0; j < 3; ++j) {
    Eigen::Matrix3d column_sum = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 3; ++i) column_sum += relative.block<3, 3>(3 * i, 3 * j);
    h.block<3, 3>(0, 3 + 3 * j) = -column_sum;
    h.block<3, 3>(3 + 3 * j, 0) = -column_sum.transpose();
  }
  h.topLeftCorner<3, 3>() = -(h.block<3, 3>(0, 3) + h.block<3, 3>(0, 6) + h.block<3, 3>(0, 9));
  return h;
}

}  // namespace psq
