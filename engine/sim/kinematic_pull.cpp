#include "engine/sim/kinematic_pull.hpp"

namespace psq {

void KinematicPull::set(std::vector<int> vertices, const Eigen::VectorXd& targets,
                        std::vector<Eigen::Vector3d> weights) {
  vertices_ = std::move(vertices);
  targets_ = targets;
  weights_ = std::move(weights);
}

double KinematicPull::value(const Eigen::VectorXd& x) {
  double sum = 0.0;
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const int v = vertices_[i];
    sum += weights_[i].dot((x.segment<3>(3 * v) - targets_.segment<3>(3 * v)).cwiseAbs2());
  }
  return 0.5 * stiffness_ * sum;
}

void KinematicPull::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const int v = vertices_[i];
    g.segment<3>(3 * v) +=
        stiffness_ * weights_[i].cwiseProduct(x.segment<3>(3 * v) - targets_.segment<3>(3 * v));
  }
}

void KinematicPull::hessian(const Eigen::VectorXd& /*x*/,
                            const std::vector<bool>& /*fixed_vertices*/, bool /*project_psd*/,
                            Eigen::VectorXd& diagonal, ElementMatrices& blocks) {
  blocks.reset(0, {});
  for (std::size_t i = 0; i < vertices_.size(); ++i)
    diagonal.segment<3>(3 * vertices_[i]) += stiffness_ * weights_[i];
}

}  // namespace psq
