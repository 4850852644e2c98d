#include "engine/contact/edge_edge_mollifier.hpp"

#include <Eigen/Geometry>
#include <array>

namespace psq {
namespace {

/// Fraction of ‖ēa‖²‖ēb‖² below which c = ‖ea × eb‖² is mollified (IPC's choice).
constexpr double kMollifierFraction = 1e-3;

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

}  // namespace

double edge_edge_mollifier_threshold(const Eigen::Vector3d& ea0_rest,
                                     const Eigen::Vector3d& ea1_rest,
                                     const Eigen::Vector3d& eb0_rest,
                                     const Eigen::Vector3d& eb1_rest) {
  return kMollifierFraction * (ea1_rest - ea0_rest).squaredNorm() *
         (eb1_rest - eb0_rest).squaredNorm();
}

StencilDerivatives<12> edge_edge_cross_squared_norm(const Eigen::Vector3d& ea0,
                                                    const Eigen::Vector3d& ea1,
                                                    const Eigen::Vector3d& eb0,
                                                    const Eigen::Vector3d& eb1) {
  const Eigen::Vector3d u = ea1 - ea0;
  const Eigen::Vector3d v = eb1 - eb0;
  const Eigen::Vector3d n = u.cross(v);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();

  // Derivatives with respect to (u, v); each vertex enters one of them with sign ∓.
  const std::array<Eigen::Vector3d, 2> g{2 * v.cross(n), 2 * n.cross(u)};
  const Eigen::Matrix3d h_uv = 2 * (cross_matrix(v) * cross_matrix(u) - cross_matrix(n));
  const std::array<std::array<Eigen::Matrix3d, 2>, 2> h{{
      {2 * (v.squaredNorm() * I - v * v.transpose()), h_uv},
      {h_uv.transpose(), 2 * (u.squaredNorm() * I - u * u.transpose())},
  }};
  constexpr std::array<int, 4> kEdge{0, 0, 1, 1};
  constexpr std::array<double, 4> kSign{-1, 1, -1, 1};

  StencilDerivatives<12> c;
  c.value = n.squaredNorm();
  for (int i = 0; i < 4; ++i) {
    c.gradient.segment<3>(3 * i) = kSign[i] * g[kEdge[i]];
    for (int j = 0; j < 4; ++j)
      c.hessian.block<3, 3>(3 * i, 3 * j) = kSign[i] * kSign[j] * h[kEdge[i]][kEdge[j]];
  }
  return c;
}

double edge_edge_mollifier(double c, double threshold) {
  if (c >= threshold) return 1;
  const double x = c / threshold;
  return (2 - x) * x;
}

double edge_edge_mollifier_first_derivative(double c, double threshold) {
  if (c >= threshold) return 0;
  return 2 / threshold * (1 - c / threshold);
}

double edge_edge_mollifier_second_derivative(double c, double threshold) {
  if (c >= threshold) return 0;
  return -2 / (threshold * threshold);
}

StencilDerivatives<12> edge_edge_mollifier(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                           const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1,
                                           double threshold) {
  const StencilDerivatives<12> c = edge_edge_cross_squared_norm(ea0, ea1, eb0, eb1);
  return chain_rule(edge_edge_mollifier(c.value, threshold),
                    edge_edge_mollifier_first_derivative(c.value, threshold),
                    edge_edge_mollifier_second_derivative(c.value, threshold), c);
}

}  // namespace psq
