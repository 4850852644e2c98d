#include "engine/sim/incremental_potential.hpp"

namespace psq {

IncrementalPotential::IncrementalPotential(const ShellSystem& system, double time_step)
    : system_(system),
      inertia_weight_(1.0 / (time_step * time_step)),
      previous_(flat(system.rest_mesh().vertices)) {}

double IncrementalPotential::elastic_energy(const Eigen::VectorXd& x) const {
  double e = 0.0;
  for (const auto& m : system_.membranes()) e += m.value(x);
  for (const auto& b : system_.bendings()) e += b.value(x);
  return e;
}

double IncrementalPotential::value(const Eigen::VectorXd& x) {
  const Eigen::VectorXd dx = x - previous_;
  const double inertia = 0.5 * inertia_weight_ * dx.dot(system_.dof_masses().cwiseProduct(dx));
  return inertia + elastic_energy(x) - system_.external_force().dot(x);
}

void IncrementalPotential::gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  g = inertia_weight_ * system_.dof_masses().cwiseProduct(x - previous_) - system_.external_force();
  for (const auto& m : system_.membranes()) m.add_gradient(x, g);
  for (const auto& b : system_.bendings()) b.add_gradient(x, g);
}

void IncrementalPotential::hessian(const Eigen::VectorXd& x, HessianBlocks& H) {
  H.diagonal = inertia_weight_ * system_.dof_masses();
  const std::size_t shells = system_.membranes().size();
  H.batches.resize(2 * shells);
  for (std::size_t s = 0; s < shells; ++s) {
    system_.membranes()[s].hessian(x, H.batches[2 * s]);
    system_.bendings()[s].hessian(x, H.batches[2 * s + 1]);
  }
}

}  // namespace psq
