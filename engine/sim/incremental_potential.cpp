#include "engine/sim/incremental_potential.hpp"

#include <algorithm>

namespace psq {

IncrementalPotential::IncrementalPotential(const ShellSystem& system, double time_step,
                                           const ElasticModel* elastics)
    : system_(system),
      elastics_(elastics),
      inertia_weight_(1.0 / (time_step * time_step)),
      previous_(flat(system.rest_mesh().vertices)) {}

void IncrementalPotential::add_term(PotentialTerm& term) { terms_.push_back(&term); }

void IncrementalPotential::remove_term(const PotentialTerm& term) { std::erase(terms_, &term); }

double IncrementalPotential::elastic_energy(const Eigen::VectorXd& x) const {
  if (elastics_) return elastics_->elastic_energy(x);
  double e = 0.0;
  for (const auto& m : system_.membranes()) e += m.value(x);
  for (const auto& b : system_.bendings()) e += b.value(x);
  return e;
}

double IncrementalPotential::value(const Eigen::VectorXd& x) {
  const Eigen::VectorXd dx = x - previous_;
  const double inertia = 0.5 * inertia_weight_ * dx.dot(system_.dof_masses().cwiseProduct(dx));
  double e = inertia + (elastics_ ? elastics_->energy(x)
                                  : elastic_energy(x) - system_.external_force().dot(x));
  for (PotentialTerm* term : terms_) e += term->value(x);
  return e;
}

void IncrementalPotential::base_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  g = inertia_weight_ * system_.dof_masses().cwiseProduct(x - previous_);
  if (elastics_) {
    elastics_->add_gradient(x, g);
    return;
  }
  g -= system_.external_force();
  for (const auto& m : system_.membranes()) m.add_gradient(x, g);
  for (const auto& b : system_.bendings()) b.add_gradient(x, g);
}

void IncrementalPotential::gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  base_gradient(x, g);
  for (PotentialTerm* term : terms_) term->add_gradient(x, g);
}

void IncrementalPotential::static_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  gradient(x, g);
  g -= inertia_weight_ * system_.dof_masses().cwiseProduct(x - previous_);
}

void IncrementalPotential::hessian(const Eigen::VectorXd& x, HessianBlocks& H) {
  H.diagonal = inertia_weight_ * system_.dof_masses();
  std::size_t elastic_batches = 0;
  if (elastics_) {
    elastics_->hessian(x, H.batches, H.project);
    elastic_batches = H.batches.size();
  } else {
    const std::size_t shells = system_.membranes().size();
    elastic_batches = 2 * shells;
    H.batches.resize(elastic_batches);
    for (std::size_t s = 0; s < shells; ++s) {
      system_.membranes()[s].hessian(x, H.batches[2 * s], H.project);
      system_.bendings()[s].hessian(x, H.batches[2 * s + 1], H.project);
    }
  }
  H.batches.resize(elastic_batches + terms_.size());
  for (std::size_t t = 0; t < terms_.size(); ++t)
    terms_[t]->hessian(x, H.fixed_vertices, H.project, H.diagonal,
                       H.batches[elastic_batches + t]);
}

double IncrementalPotential::max_feasible_step(const Eigen::VectorXd& x,
                                               const Eigen::VectorXd& dx) {
  double step = 1.0;
  for (PotentialTerm* term : terms_) step = std::min(step, term->max_feasible_step(x, dx));
  return step;
}

}  // namespace psq
