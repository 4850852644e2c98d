#include "engine/progressive/target_relaxation.hpp"

#include <chrono>
#include <cmath>

#include "engine/progressive/local_solve.hpp"
#include "engine/sim/strain_limit_term.hpp"
#include "engine/solver/newton.hpp"

namespace psq {
namespace {

/// Newton iterations between two κ updates, and the budget of the relaxation.
constexpr int kIterationsPerUpdate = 10;
constexpr int kMaxIterations = 50;
/// Newton's step tolerance as a fraction of d̂: the level's solve takes over from here, so the
/// relaxation only has to bring each vertex to its place at the barrier's scale.
constexpr double kRelaxTolerance = 1e-2;

}  // namespace

TargetPull::TargetPull(Eigen::VectorXd target, ContactTerm& contact)
    : target_(std::move(target)), contact_(contact) {}

double TargetPull::value(const Eigen::VectorXd& x) {
  return 0.5 * (x - target_).squaredNorm() + contact_.value(x);
}

void TargetPull::gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  g = x - target_;
  contact_.add_gradient(x, g);
}

void TargetPull::hessian(const Eigen::VectorXd& x, HessianBlocks& H) {
  H.diagonal = Eigen::VectorXd::Ones(size());
  H.batches.resize(1);
  contact_.hessian(x, H.diagonal, H.batches[0]);
}

double TargetPull::max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) {
  return contact_.max_feasible_step(x, dx);
}

RelaxationStats relax_toward_targets(const ShellSystem& fine, const Eigen::VectorXd& target,
                                     double safe_gap, Eigen::VectorXd& x) {
  ContactTerm contact(fine);
  const double reach = contact.potential().parameters().band.activation_distance;
  const Eigen::Index n = x.size() / 3;
  std::vector<bool> freed(n, false);
  if (strain_limit_enabled(fine.scene()))
    for (Eigen::Index v = 0; v < n; ++v)
      freed[v] = (x.segment<3>(3 * v) - target.segment<3>(3 * v)).norm() > reach;
  for (const ContactPair& pair : contact.potential().active_pairs(x))
    if (std::sqrt(pair_distance(pair, x)) < safe_gap)
      for (int v : pair.vertices) freed[v] = true;
  return relax_free_vertices(contact, target, movable_vertex_dofs(fine, freed), x);
}

RelaxationStats relax_free_vertices(ContactTerm& contact, const Eigen::VectorXd& target,
                                    const DofMap& dofs, Eigen::VectorXd& x) {
  const auto started = std::chrono::steady_clock::now();
  RelaxationStats stats;
  stats.vertices = static_cast<int>(dofs.free_size() / 3);
  if (stats.vertices == 0) return stats;
  balance_barrier_stiffness(contact, x, x - target, dofs);

  TargetPull pull(target, contact);
  NewtonSolver newton;
  NewtonSettings settings;
  settings.max_iterations = kIterationsPerUpdate;
  settings.tolerance = kRelaxTolerance * contact.potential().parameters().band.activation_distance;
  for (int done = 0; done < kMaxIterations; done += kIterationsPerUpdate) {
    const NewtonResult result = newton.minimize(pull, x, dofs, settings);
    stats.iterations += result.iterations;
    if (result.converged || result.stagnated) break;
    contact.update_stiffness(x, false);
  }
  stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return stats;
}

}  // namespace psq
