#include "engine/progressive/target_relaxation.hpp"

#include <chrono>
#include <cmath>
#include <set>

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

void balance_barrier_stiffness(ContactTerm& contact, const Eigen::VectorXd& x,
                               const Eigen::VectorXd& gradient, const DofMap& dofs) {
  std::vector<bool> free(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) free[i] = dofs.reduced(i) >= 0;
  // IPC's κ_min scales with the Hessian's diagonal, which it takes as m̄/Δt²; here it is one.
  contact.initialize_stiffness(x, gradient, free, 1.0 / contact.average_mass());
}

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
  const auto started = std::chrono::steady_clock::now();
  ContactTerm contact(fine);
  const double reach = contact.potential().parameters().band.activation_distance;
  std::set<int> freed;
  const Eigen::Index n = x.size() / 3;
  if (strain_limit_enabled(fine.scene()))
    for (Eigen::Index v = 0; v < n; ++v)
      if ((x.segment<3>(3 * v) - target.segment<3>(3 * v)).norm() > reach)
        freed.insert(static_cast<int>(v));
  for (const ContactPair& pair : contact.potential().active_pairs(x))
    if (std::sqrt(pair_distance(pair, x)) < safe_gap)
      for (int v : pair.vertices) freed.insert(v);
  for (const PinnedVertex& pin : fine.pinned()) freed.erase(pin.vertex);

  RelaxationStats stats;
  stats.vertices = static_cast<int>(freed.size());
  if (freed.empty()) return stats;
  std::vector<int> fixed;
  for (Eigen::Index v = 0; v < n; ++v)
    if (!freed.contains(static_cast<int>(v))) fixed.push_back(static_cast<int>(v));
  const DofMap dofs(n, fixed);
  balance_barrier_stiffness(contact, x, x - target, dofs);

  TargetPull pull(target, contact);
  NewtonSolver newton;
  NewtonSettings settings;
  settings.max_iterations = kIterationsPerUpdate;
  settings.tolerance = kRelaxTolerance * reach;
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
