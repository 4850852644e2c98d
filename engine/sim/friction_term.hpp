#pragma once
// Lagged IPC friction as a term of the incremental potential
// (docs/friction-and-strain-limiting.md): a FrictionPotential over the contact term's pairs within
// reach, lagged at a given state, with the scene's friction coefficient of each pair of bodies and
// its slip threshold ε = ε_v Δt.

#include <vector>

#include "engine/contact/contact_potential.hpp"
#include "engine/contact/friction.hpp"
#include "engine/sim/potential_term.hpp"
#include "engine/sim/shell_system.hpp"

namespace psq {

/// μ of every pair of bodies, numbered as in contact_surface (shells first, then colliders):
/// [contact] friction, overridden by the scene's [[contact.pair]] entries.
class BodyFrictionTable {
 public:
  /// @throws InputError for a pair naming no shell or collider of the scene.
  explicit BodyFrictionTable(const Scene& scene);

  [[nodiscard]] double between(int body_a, int body_b) const {
    return coefficients_[static_cast<std::size_t>(body_a * body_count_ + body_b)];
  }
  /// Whether some pair of bodies has μ > 0.
  [[nodiscard]] bool any_friction() const;

 private:
  int body_count_;
  std::vector<double> coefficients_;  ///< body_count² entries, symmetric
};

/// Whether `scene` simulates friction: contact on and μ > 0 for some pair of bodies.
bool friction_enabled(const Scene& scene);

/// ε_v [m per unit time]: the scene's friction_slip_velocity, else 1e-3 × the bounding-box
/// diagonal of the rest state (shells and colliders) per unit time.
double friction_slip_velocity(const ShellSystem& system);

class FrictionTerm : public PotentialTerm {
 public:
  /// The friction of `system`'s scene with the slip threshold ε = ε_v·time_step; no contact is
  /// lagged yet (the term is zero until lag()).
  FrictionTerm(const ShellSystem& system, double time_step);

  /// Freezes friction at `lagged_state` for the step from `step_start`: every pair of
  /// `contact` within reach there with μ > 0 and a normal force λ > 0 (from the contact's
  /// current κ and the pair's barrier weight) becomes a lagged contact.
  void lag(ContactPotential& contact, const Eigen::VectorXd& lagged_state,
           const Eigen::VectorXd& step_start);

  /// The lagged contacts (μλ > 0).
  [[nodiscard]] int contact_count() const { return potential_.contact_count(); }
  /// ε = ε_v Δt [m].
  [[nodiscard]] double slip_threshold() const { return slip_threshold_; }

  /// Time spent lagging and evaluating the term since the last reset [s] (benchmarks).
  [[nodiscard]] double seconds() const { return seconds_; }
  void reset_seconds() { seconds_ = 0; }

  double value(const Eigen::VectorXd& x) override;
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override;
  void hessian(const Eigen::VectorXd& x, const std::vector<bool>& fixed_vertices,
               bool project_psd, Eigen::VectorXd& diagonal, ElementMatrices& blocks) override;

 private:
  BodyFrictionTable coefficients_;
  double slip_threshold_;
  FrictionPotential potential_;
  double seconds_ = 0;
};

}  // namespace psq
