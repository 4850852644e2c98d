#include "engine/progressive/target_relaxation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "engine/contact/contact_potential.hpp"
#include "engine/progressive/local_solve.hpp"
#include "engine/sim/strain_limit_term.hpp"
#include "engine/solver/newton.hpp"

namespace psq {
namespace {

/// Newton iterations between two κ updates, and the budget of one stiffness round.
constexpr int kIterationsPerUpdate = 10;
constexpr int kMaxIterations = 50;
/// Newton's step tolerance as a fraction of the smaller of g and d̂: the level's solve takes over
/// from here, so the relaxation only has to bring each vertex to its place at the scale of the
/// gap it restores.
constexpr double kRelaxTolerance = 1e-2;
/// The gap is restored when every pair with a freed vertex is at least this fraction of g apart:
/// the pull toward targets that lie closer than g keeps the balance just below g.
constexpr double kRestoredGapFraction = 0.5;
/// Stiffness rounds after the first, each with κ this many times larger (§4.4.3: "an increasing
/// schedule of barrier stiffness"): the balanced distance of a pair grows about in proportion to
/// κ, so three rounds take a pair from 1e-3 g to g.
constexpr int kStiffnessRounds = 3;
constexpr double kStiffnessGrowth = 10.0;

/// The smallest distance of x's active pairs that have a vertex `dofs` frees (infinity when
/// there is none).
double closest_free_pair(ContactTerm& contact, const DofMap& dofs, const Eigen::VectorXd& x) {
  double closest = std::numeric_limits<double>::infinity();
  for (const ContactPair& pair : contact.potential().active_pairs(x))
    for (int v : pair.vertices)
      if (v >= 0 && dofs.reduced(3 * static_cast<Eigen::Index>(v)) >= 0) {
        closest = std::min(closest, std::sqrt(pair_distance(pair, x)));
        break;
      }
  return closest;
}

}  // namespace

TargetPull::TargetPull(Eigen::VectorXd target, ContactTerm& contact,
                       const Confinement& confinement)
    : target_(std::move(target)), contact_(contact), confinement_(confinement) {}

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
  contact_.hessian(x, H.fixed_vertices, H.project, H.diagonal, H.batches[0]);
}

double TargetPull::max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) {
  return std::min(confinement_.max_step(x, dx), contact_.max_feasible_step(x, dx));
}

RelaxationStats relax_toward_targets(const ShellSystem& fine, const Eigen::VectorXd& target,
                                     double safe_gap, Eigen::VectorXd& x) {
  const ContactSurface surface = contact_surface(fine, fine.scene().contact.self_contact);
  const ContactParameters parameters = contact_parameters(fine);
  const double reach = parameters.band.activation_distance;
  const Eigen::Index n = x.size() / 3;
  std::vector<bool> freed(n, false);
  if (strain_limit_enabled(fine.scene()))
    for (Eigen::Index v = 0; v < n; ++v)
      freed[v] = (x.segment<3>(3 * v) - target.segment<3>(3 * v)).norm() > reach;
  ContactPotential whole(surface, parameters);
  for (const ContactPair& pair : whole.active_pairs(x))
    if (std::sqrt(pair_distance(pair, x)) < safe_gap)
      for (int v : pair.vertices)
        if (v >= 0) freed[v] = true;
  // Held whole, even with free components: the relaxation only makes room (safe_refinement).
  for (const PinnedVertex& pin : fine.pinned()) freed[pin.vertex] = false;
  Positions p = as_positions(x);
  const RelaxationStats stats =
      relax_on_patch(surface, parameters, fine.scene().contact.stiffness,
                     bounding_box_diagonal(fine.rest_mesh().vertices), freed,
                     as_positions(target), safe_gap, p);
  x = flat(p);
  return stats;
}

RelaxationStats relax_on_patch(const ContactSurface& surface, const ContactParameters& parameters,
                               std::optional<double> fixed_stiffness, double bbox_diagonal,
                               const std::vector<bool>& freed, const Positions& target,
                               double safe_gap, Positions& x) {
  if (std::none_of(freed.begin(), freed.end(), [](bool f) { return f; })) return {};
  RelaxationPatch patch = relaxation_patch(
      surface, x, target, freed, parameters.band.thickness + parameters.band.activation_distance);
  const auto m = static_cast<Eigen::Index>(patch.vertex.size());
  Positions patch_x(m, 3), patch_target(m, 3);
  std::vector<int> held;
  for (Eigen::Index k = 0; k < m; ++k) {
    patch_x.row(k) = x.row(patch.vertex[k]);
    patch_target.row(k) = target.row(patch.vertex[k]);
    if (!patch.freed[k]) held.push_back(static_cast<int>(k));
  }
  // The mass enters κ's balance only as m̄ times its 1/m̄ (balance_barrier_stiffness).
  ContactTerm contact(std::move(patch.surface), parameters, fixed_stiffness, bbox_diagonal, 1.0);
  Eigen::VectorXd relaxed = flat(patch_x);
  const RelaxationStats stats = relax_free_vertices(contact, flat(patch_target), DofMap(m, held),
                                                    safe_gap, relaxed, patch.confinement);
  for (Eigen::Index k = 0; k < m; ++k)
    if (patch.freed[k]) x.row(patch.vertex[k]) = relaxed.segment<3>(3 * k).transpose();
  return stats;
}

RelaxationStats relax_free_vertices(ContactTerm& contact, const Eigen::VectorXd& target,
                                    const DofMap& dofs, double safe_gap, Eigen::VectorXd& x,
                                    const Confinement& confinement) {
  const auto started = std::chrono::steady_clock::now();
  RelaxationStats stats;
  stats.vertices = static_cast<int>(dofs.free_size() / 3);
  if (stats.vertices == 0) return stats;
  balance_barrier_stiffness(contact, x, x - target, dofs);

  TargetPull pull(target, contact, confinement);
  NewtonSolver newton;
  NewtonSettings settings;
  settings.max_iterations = kIterationsPerUpdate;
  settings.tolerance =
      kRelaxTolerance *
      std::min(safe_gap, contact.potential().parameters().band.activation_distance);
  for (int round = 0;; ++round) {
    for (int done = 0; done < kMaxIterations; done += kIterationsPerUpdate) {
      const NewtonResult result = newton.minimize(pull, x, dofs, settings);
      stats.iterations += result.iterations;
      if (result.converged || result.stagnated) break;
      contact.update_stiffness(x, false);
    }
    if (round == kStiffnessRounds ||
        closest_free_pair(contact, dofs, x) >= kRestoredGapFraction * safe_gap)
      break;
    contact.scale_stiffness(kStiffnessGrowth);
  }
  stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return stats;
}

}  // namespace psq
