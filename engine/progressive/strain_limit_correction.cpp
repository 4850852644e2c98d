#include "engine/progressive/strain_limit_correction.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <string>

#include "engine/core/error.hpp"
#include "engine/progressive/local_solve.hpp"
#include "engine/solver/newton.hpp"

namespace psq {
namespace {

/// s_c = s̄ − kCorrectionTarget·δ: the stretch the excess is measured from.
constexpr double kCorrectionTarget = 0.2;
/// The correction is needed, and done, when some triangle is (still) above s̄ − kCorrectionSlack·δ:
/// the level's barrier then starts with at least a tenth of its band as slack.
constexpr double kCorrectionSlack = 0.1;
/// A correction that cannot reach s̄ − kCorrectionSlack·δ is still taken when every triangle is
/// below s̄ − kFeasibleSlack·δ: the level's barrier is finite there and its solve takes over.
constexpr double kFeasibleSlack = 1e-3;
/// ρ of the proximity term. V's Gauss–Newton curvature 2Ā|β|² is of order one at any scale
/// (Ā ∝ ℓ², |β| ∝ 1/ℓ), so a fixed ρ four orders below it keeps the Hessian definite without
/// holding the vertices back.
constexpr double kProximityWeight = 1e-4;
/// Newton iterations between two feasibility checks, and the budget of one solve.
constexpr int kCheckEvery = 5;
constexpr int kMaxIterations = 100;
/// A solve ends early when its best state has not improved by this fraction of the tightest
/// triangle's remaining excess over kStalledChecks checks in a row: the vertices it moves cannot
/// restore the limit. The tightest triangle is a maximum over a sum Newton minimizes, so one
/// check may be worse than the one before while the sum still falls, and the best one may
/// stand for several checks before the sum's descent lowers it again.
constexpr double kLeastProgress = 0.01;
constexpr int kStalledChecks = 6;
/// Newton's step tolerance, relative to the bounding-box diagonal: the correction needs the
/// stretches below their accepted bound, not the minimizer of V to many digits.
constexpr double kCorrectionTolerance = 1e-6;

/// σ₁ of a triangle and its gradient direction ∂σ₁/∂F = u₁v₁ᵀ.
struct LargestStretch {
  double sigma;
  DeformationGradient direction;
};

LargestStretch largest_stretch(const TrianglePositions& x, const MembraneRest& rest) {
  const Eigen::JacobiSVD<DeformationGradient> svd(deformation_gradient(x, rest),
                                                  Eigen::ComputeFullU | Eigen::ComputeFullV);
  return {svd.singularValues()[0], svd.matrixU().col(0) * svd.matrixV().col(0).transpose()};
}

}  // namespace

StretchExcess::StretchExcess(const ShellSystem& system, Eigen::VectorXd start,
                             ContactTerm* contact)
    : start_(std::move(start)), contact_(contact) {
  for (int s = 0; s < static_cast<int>(system.shells().size()); ++s) {
    const Shell& shell = system.scene().shells[s];
    if (!shell.strain_limit) continue;
    const double limit = shell.strain_limit->limit;
    const double band = limit - 1.0;
    shells_.push_back({shell.name,
                       TriangleElements(system.shell_rest_mesh(s),
                                        system.shells()[s].first_vertex, "strain-limit correction"),
                       limit, limit - kCorrectionTarget * band, limit - kCorrectionSlack * band});
  }
}

double StretchExcess::value(const Eigen::VectorXd& x) {
  double energy = 0.5 * kProximityWeight * (x - start_).squaredNorm();
  if (contact_) energy += contact_->value(x);
  for (const LimitedShell& shell : shells_)
    for (std::size_t t = 0; t < shell.triangles.size(); ++t) {
      const double excess = std::max(
          0.0, largest_stretch(shell.triangles.positions(x, t), shell.triangles.rest(t)).sigma -
                   shell.target);
      energy += shell.triangles.rest(t).area * excess * excess;
    }
  return energy;
}

void StretchExcess::gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  excess_gradient(x, g);
  if (contact_) contact_->add_gradient(x, g);
}

void StretchExcess::excess_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  g = kProximityWeight * (x - start_);
  for (const LimitedShell& shell : shells_)
    for (std::size_t t = 0; t < shell.triangles.size(); ++t) {
      const MembraneRest& rest = shell.triangles.rest(t);
      const LargestStretch stretch = largest_stretch(shell.triangles.positions(x, t), rest);
      const double excess = stretch.sigma - shell.target;
      if (excess <= 0) continue;
      const TriangleVector local =
          pull_back_stress(stretch.direction, rest, 2 * rest.area * excess);
      for (int i = 0; i < 3; ++i)
        g.segment<3>(3 * shell.triangles.stencils()[3 * t + i]) += local.segment<3>(3 * i);
    }
}

void StretchExcess::hessian(const Eigen::VectorXd& x, HessianBlocks& H) {
  H.diagonal = Eigen::VectorXd::Constant(size(), kProximityWeight);
  std::vector<int> stencils;
  std::vector<TriangleMatrix> blocks;
  for (const LimitedShell& shell : shells_)
    for (std::size_t t = 0; t < shell.triangles.size(); ++t) {
      const MembraneRest& rest = shell.triangles.rest(t);
      const LargestStretch stretch = largest_stretch(shell.triangles.positions(x, t), rest);
      if (stretch.sigma <= shell.target) continue;
      const DeformationGradientVector direction =
          Eigen::Map<const DeformationGradientVector>(stretch.direction.data());
      blocks.push_back(
          pull_back_stress_derivative(direction * direction.transpose(), rest, 2 * rest.area));
      for (int i = 0; i < 3; ++i) stencils.push_back(shell.triangles.stencils()[3 * t + i]);
    }
  H.batches.resize(contact_ ? 2 : 1);
  H.batches[0].reset(3, std::move(stencils));
  for (std::size_t e = 0; e < blocks.size(); ++e) H.batches[0].block(e) = blocks[e];
  if (contact_) contact_->hessian(x, H.fixed_vertices, H.project, H.diagonal, H.batches[1]);
}

double StretchExcess::max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) {
  return contact_ ? contact_->max_feasible_step(x, dx) : 1.0;
}

StretchExcess::Tightest StretchExcess::tightest(const Eigen::VectorXd& x) const {
  Tightest tightest;
  bool feasible = true;
  double worst = -std::numeric_limits<double>::infinity();
  for (const LimitedShell& shell : shells_)
    for (std::size_t t = 0; t < shell.triangles.size(); ++t) {
      const double sigma =
          largest_stretch(shell.triangles.positions(x, t), shell.triangles.rest(t)).sigma;
      const double slack = (shell.limit - shell.accepted) * (kFeasibleSlack / kCorrectionSlack);
      feasible = feasible && sigma <= shell.limit - slack;
      if (sigma - shell.accepted > worst) {
        worst = sigma - shell.accepted;
        tightest = {shell.name, shell.limit, shell.accepted, sigma, sigma <= shell.accepted};
      }
    }
  tightest.feasible = feasible;
  return tightest;
}

StrainCorrectionStats correct_strain_limits(const ShellSystem& fine,
                                            const std::vector<bool>& inserted, int level,
                                            Eigen::VectorXd& x) {
  const auto started = std::chrono::steady_clock::now();
  if (static_cast<Eigen::Index>(inserted.size()) != fine.rest_mesh().vertex_count())
    throw std::invalid_argument(fmt::format("correct_strain_limits: {} vertex marks for {} vertices",
                                            inserted.size(), fine.rest_mesh().vertex_count()));
  StretchExcess excess(fine, x, nullptr);
  StrainCorrectionStats stats;
  const StretchExcess::Tightest start = excess.tightest(x);
  if (start.shell.empty()) return stats;
  stats.stretch_before = stats.stretch_after = start.sigma / start.limit;
  if (start.acceptable) return stats;

  std::unique_ptr<ContactTerm> contact;
  if (contact_enabled(fine.scene())) {
    contact = std::make_unique<ContactTerm>(fine);
    excess.set_contact(contact.get());
  }
  NewtonSolver newton;
  NewtonSettings settings;
  settings.max_iterations = kCheckEvery;
  settings.tolerance = kCorrectionTolerance * bounding_box_diagonal(fine.rest_mesh().vertices);
  // One solve over the free DOFs of `dofs`; x ends at the best state it passed (the least
  // tightest excess), which it returns.
  const auto solve = [&](const DofMap& dofs) {
    StretchExcess::Tightest best = excess.tightest(x);
    if (dofs.free_size() == 0) return best;
    if (contact) {
      Eigen::VectorXd g;
      excess.excess_gradient(x, g);
      balance_barrier_stiffness(*contact, x, g, dofs);
    }
    Eigen::VectorXd best_x = x;
    int stalled = 0;
    for (int done = 0; done < kMaxIterations; done += kCheckEvery) {
      const NewtonResult result = newton.minimize(excess, x, dofs, settings);
      stats.iterations += result.iterations;
      const StretchExcess::Tightest now = excess.tightest(x);
      const bool improved = now.excess() < best.excess() - kLeastProgress * best.excess();
      stalled = improved ? 0 : stalled + 1;
      if (now.excess() < best.excess()) {
        best = now;
        best_x = x;
      }
      if (best.acceptable || result.converged || result.stagnated || stalled == kStalledChecks)
        break;
      if (contact) contact->update_stiffness(x, false);
    }
    x = best_x;
    return best;
  };
  StretchExcess::Tightest end = solve(movable_vertex_dofs(fine, inserted));
  if (!end.acceptable) {
    stats.freed_old_vertices = true;
    end = solve(movable_vertex_dofs(fine, std::vector<bool>(inserted.size(), true)));
  }
  stats.stretch_after = end.sigma / end.limit;
  stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!end.feasible)
    throw NumericalError(fmt::format(
        "refinement into level {}: shell '{}' keeps a principal stretch of {:.6g} after the "
        "strain-limit correction (its strain_limit is {:.6g}); use fewer [hierarchy] levels or "
        "a larger vertex_ratio",
        level, end.shell, end.sigma, end.limit));
  return stats;
}

}  // namespace psq
