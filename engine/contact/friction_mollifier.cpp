#include "engine/contact/friction_mollifier.hpp"

namespace psq {

double friction_mollifier(double y, double slip_threshold) {
  const double eps = slip_threshold;
  if (y >= eps) return y;
  return y * y * (1 - y / (3 * eps)) / eps + eps / 3;
}

double friction_mollifier_derivative(double y, double slip_threshold) {
  const double eps = slip_threshold;
  if (y >= eps) return 1;
  return y * (2 - y / eps) / eps;
}

double friction_mollifier_derivative_over_norm(double y, double slip_threshold) {
  const double eps = slip_threshold;
  if (y >= eps) return 1 / y;
  return (2 - y / eps) / eps;
}

double friction_mollifier_second_derivative(double y, double slip_threshold) {
  const double eps = slip_threshold;
  if (y >= eps) return 0;
  return 2 * (eps - y) / (eps * eps);
}

Eigen::Vector2d friction_mollifier_gradient(const Eigen::Vector2d& u, double slip_threshold) {
  return friction_mollifier_derivative_over_norm(u.norm(), slip_threshold) * u;
}

Eigen::Matrix2d friction_mollifier_hessian(const Eigen::Vector2d& u, double slip_threshold) {
  const double y = u.norm();
  const double across = friction_mollifier_derivative_over_norm(y, slip_threshold);
  if (y == 0) return across * Eigen::Matrix2d::Identity();
  const double along = friction_mollifier_second_derivative(y, slip_threshold);
  const Eigen::Vector2d direction = u / y;
  const Eigen::Matrix2d along_projector = direction * direction.transpose();
  return across * (Eigen::Matrix2d::Identity() - along_projector) + along * along_projector;
}

}  // namespace psq
