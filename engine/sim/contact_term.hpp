#pragma once
// IPC contact as a term of the incremental potential: the contact surface of a ShellSystem
// (every shell and collider), the scene's [contact] settings resolved to parameters, and the
// barrier stiffness κ chosen and adapted as in IPC.

#include <map>
#include <optional>
#include <string>

#include "engine/contact/contact_potential.hpp"
#include "engine/sim/potential_term.hpp"
#include "engine/sim/shell_system.hpp"

namespace psq {

/// Whether the scene simulates contact: [contact] enabled when given, otherwise on when the
/// scene has more than one body (shells and colliders) or asks for self-contact.
bool contact_enabled(const Scene& scene);

/// Every shell and collider of the system as one contact surface. Bodies are numbered shells
/// first, then colliders. Shells touch each other and the colliders; a shell touches itself
/// only with `self_contact`; colliders never touch each other or themselves (they are rigid and
/// scripted, so their pairs could not respond).
ContactSurface contact_surface(const ShellSystem& system, bool self_contact);

/// The scene's [contact] settings as contact parameters; d̂ defaults to 1e-3 × the bounding-box
/// diagonal of the rest state (shells and colliders).
ContactParameters contact_parameters(const ShellSystem& system);

class ContactTerm : public PotentialTerm {
 public:
  /// The contact term of `system` with its scene's settings. κ starts at the scene's
  /// `stiffness` when given (then it stays fixed), else at 0 until initialize_stiffness.
  explicit ContactTerm(const ShellSystem& system);
  /// The contact term of any surface (a partly refined level's, for one batch of its safe
  /// initialization): κ fixed at `fixed_stiffness` when given; `bbox_diagonal` is l of IPC's
  /// rules, `average_mass` the mean vertex mass.
  ContactTerm(ContactSurface surface, const ContactParameters& parameters,
              std::optional<double> fixed_stiffness, double bbox_diagonal, double average_mass);

  [[nodiscard]] ContactPotential& potential() { return potential_; }
  [[nodiscard]] double stiffness() const { return potential_.stiffness(); }
  /// Mean mass of the shell vertices (colliders have none) [kg].
  [[nodiscard]] double average_mass() const { return average_mass_; }

  /// IPC's initial κ at x (initial_barrier_stiffness; never below the κ reached so far),
  /// unless the scene fixes κ:
  /// `base_gradient` is ∇ of the rest of the potential at x, `free` marks the DOFs the solver
  /// moves (the others do not enter the balance), `inertia_weight` is 1/Δt².
  void initialize_stiffness(const Eigen::VectorXd& x, const Eigen::VectorXd& base_gradient,
                            const std::vector<bool>& free, double inertia_weight);
  /// IPC's update between Newton iterations (update_barrier_stiffness): doubles κ (up to κ_max)
  /// when the smallest gap stays below ε_g = 1e-2 d̂ and shrank since the last call, and when
  /// `steps_cut_by_ccd` (the CCD cut most of the last steps short) raises it to hold the
  /// contact force at ε_g. Returns whether κ changed.
  bool update_stiffness(const Eigen::VectorXd& x, bool steps_cut_by_ccd);
  /// κ times `factor`, past IPC's rules, unless the scene fixes κ: for a relaxation that must
  /// push pairs apart to a given gap rather than balance the forces at x.
  void scale_stiffness(double factor);

  /// Adds κ, its upper bound and the last smallest distance to `state` ("contact.*"); the
  /// distance only while some pair was within reach (it is infinite otherwise).
  void save_state(std::map<std::string, double>& state) const;
  /// Takes back what save_state wrote; a missing κ or bound keeps its value, a missing distance
  /// is infinite (no pair was within reach).
  void load_state(const std::map<std::string, double>& state);

  double value(const Eigen::VectorXd& x) override { return potential_.value(x); }
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    potential_.add_gradient(x, g);
  }
  void hessian(const Eigen::VectorXd& x, const std::vector<bool>& fixed_vertices,
               bool project_psd, Eigen::VectorXd& diagonal, ElementMatrices& blocks) override;
  double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) override {
    return potential_.max_feasible_step(x, dx);
  }

 private:
  ContactPotential potential_;
  bool fixed_stiffness_;
  double bbox_diagonal_;
  double average_mass_;
  BarrierStiffness stiffness_;
  double previous_min_distance_;
};

}  // namespace psq
