#include "engine/sim/strain_limit_term.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "engine/core/error.hpp"

namespace psq {
namespace {

/// κ_s doubles up to this many times its starting value. The doubling only guards convergence
/// (feasibility is the line search's): at the start E h δ² the barrier stops a load of tension
/// T with a slack of about r ≈ E h δ/T of the band, and the update fires only below r = 1e-4,
/// i.e. for tensions beyond ~10⁴ E h δ; this cap lets κ_s follow such loads by four more
/// orders of magnitude.
constexpr double kMaxStiffnessGrowth = 1e4;

/// A step the limit cuts stops at this fraction of the way to it. σ₁ is convex along a step,
/// so every triangle then keeps at least 1 − kCutStepFraction of its slack, as the contact CCD
/// keeps a fraction of each gap. A step onto the limit itself (the bisection's 1e-12 in α)
/// leaves a triangle at the barrier's singularity, where Newton's steps shrink with the slack
/// and satisfy the step-size test without balancing the forces.
constexpr double kCutStepFraction = 0.9;

/// The barrier of shell `s`: band (1, strain_limit) and κ_s from the scene or E h δ².
StrainLimitEnergy shell_energy(const ShellSystem& system, int s) {
  const Shell& shell = system.scene().shells[s];
  const StrainLimitBand band{.limit = shell.strain_limit->limit, .band_start = 1.0};
  const double stiffness = shell.strain_limit->stiffness.value_or(initial_strain_limit_stiffness(
      shell.material.youngs_modulus * shell.material.thickness, band));
  return StrainLimitEnergy(system.shell_rest_mesh(s), band, stiffness,
                           system.shells()[s].first_vertex);
}

}  // namespace

bool strain_limit_enabled(const Scene& scene) {
  return std::any_of(scene.shells.begin(), scene.shells.end(),
                     [](const Shell& shell) { return shell.strain_limit.has_value(); });
}

StrainLimitTerm::StrainLimitTerm(const ShellSystem& system) {
  for (int s = 0; s < static_cast<int>(system.shells().size()); ++s) {
    if (!system.scene().shells[s].strain_limit) continue;
    energies_.push_back(shell_energy(system, s));
    adaptations_.push_back({system.shells()[s].name,
                            kMaxStiffnessGrowth * energies_.back().stiffness(),
                            std::numeric_limits<double>::infinity()});
  }
}

void StrainLimitTerm::require_feasible(const Eigen::VectorXd& x, const std::string& state) const {
  for (std::size_t k = 0; k < energies_.size(); ++k) {
    const double limit = energies_[k].band().limit;
    const double slack = energies_[k].min_slack(x);
    if (!(slack > 0))
      throw InputError(fmt::format(
          "shell '{}': {} stretches a triangle to a principal stretch of {:.9g}, not below the "
          "shell's strain_limit {:.9g}; raise the limit or start from a state within it",
          adaptations_[k].shell, state, limit - slack, limit));
  }
}

void StrainLimitTerm::save_state(std::map<std::string, double>& state) const {
  for (std::size_t k = 0; k < energies_.size(); ++k) {
    const std::string prefix = "strain_limit." + adaptations_[k].shell;
    state[prefix + ".stiffness"] = energies_[k].stiffness();
    state[prefix + ".previous_min_slack"] = adaptations_[k].previous_min_slack;
  }
}

void StrainLimitTerm::load_state(const std::map<std::string, double>& state) {
  for (std::size_t k = 0; k < energies_.size(); ++k) {
    const std::string prefix = "strain_limit." + adaptations_[k].shell;
    double stiffness = energies_[k].stiffness();
    load_named(state, prefix + ".stiffness", stiffness);
    energies_[k].set_stiffness(stiffness);
    load_named(state, prefix + ".previous_min_slack", adaptations_[k].previous_min_slack);
  }
}

bool StrainLimitTerm::update_stiffness(const Eigen::VectorXd& x) {
  bool changed = false;
  for (std::size_t k = 0; k < energies_.size(); ++k) {
    Adaptation& adaptation = adaptations_[k];
    StrainLimitEnergy& energy = energies_[k];
    const double slack = energy.min_slack(x);
    const double stiffness = update_strain_limit_stiffness(
        energy.stiffness(), adaptation.previous_min_slack, slack, energy.band(),
        adaptation.max_stiffness);
    changed = changed || stiffness != energy.stiffness();
    energy.set_stiffness(stiffness);
    adaptation.previous_min_slack = slack;
  }
  return changed;
}

double StrainLimitTerm::value(const Eigen::VectorXd& x) {
  double sum = 0;
  for (const StrainLimitEnergy& energy : energies_) sum += energy.value(x);
  return sum;
}

void StrainLimitTerm::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  for (const StrainLimitEnergy& energy : energies_) energy.add_gradient(x, g);
}

// Its stress derivative has no negative eigenvalue but rounding's (strain_limit.hpp), so its
// blocks are projected always: that only clamps the rounding.
void StrainLimitTerm::hessian(const Eigen::VectorXd& x,
                              const std::vector<bool>& /*fixed_vertices*/,
                              bool /*project_psd*/, Eigen::VectorXd& /*diagonal*/,
                              ElementMatrices& blocks) {
  blocks.reset(3, {});
  for (const StrainLimitEnergy& energy : energies_) {
    energy.hessian(x, shell_blocks_);
    blocks.vertices.insert(blocks.vertices.end(), shell_blocks_.vertices.begin(),
                           shell_blocks_.vertices.end());
    blocks.values.insert(blocks.values.end(), shell_blocks_.values.begin(),
                         shell_blocks_.values.end());
  }
}

double StrainLimitTerm::max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) {
  double step = 1.0;
  for (const StrainLimitEnergy& energy : energies_)
    step = std::min(step, energy.max_feasible_step(x, dx));
  return step < 1.0 ? kCutStepFraction * step : step;
}

}  // namespace psq
