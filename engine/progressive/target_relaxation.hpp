#pragma once
// Patch relaxation of a safe initialization (paper §4.4.3). The CCD advances of
// safe_refinement.hpp stop each vertex of a limiting pair where the pair limited it, so pairs can
// end far closer than the safe gap g, which the level's barrier then meets at its singular end. The
// relaxation frees the vertices of pairs closer than g and minimizes
//   R(y) = ½ Σ_v ‖y_v − t_v‖² + κ B(y)
// over them, t the prolonged targets, B the scene's contact barrier with κ from IPC's balance
// with the pull, by Newton with CCD-cut steps: the pairs are pushed back toward d̂ while each
// vertex stays as near its target as the barrier allows. Where the balance leaves a pair closer
// than g/2, κ is raised tenfold and the solve repeated ("an increasing schedule of barrier
// stiffness, until the balance ... restores the gap", §4.4.3): the balanced distance of a pair
// pulled together grows about in proportion to κ.
//
// With a strain limit it also frees the stragglers, the vertices farther than d̂ from their
// targets: a vertex whose target lies beyond an obstacle (a child of cloth resting on a sphere,
// whose target dips below the sphere's facets) stays near its parent, up to a coarse edge away,
// and its triangles are stretched several times over, more than the strain-limit correction
// can take back against the contact. Without a strain limit the level's
// solve corrects such elements with its own physics, and a pull toward the targets would only
// change its path. Every accepted step is intersection-free by the CCD; the caller's exact check
// stays the judge.

#include <Eigen/Core>
#include <vector>

#include "engine/progressive/relaxation_patch.hpp"
#include "engine/sim/contact_term.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/solver/dof_map.hpp"
#include "engine/solver/objective.hpp"

namespace psq {

/// R above over a system's vertices.
class TargetPull final : public Objective {
 public:
  /// `contact` and `confinement` (whose boxes cut every step) must outlive this objective.
  TargetPull(Eigen::VectorXd target, ContactTerm& contact, const Confinement& confinement);

  [[nodiscard]] Eigen::Index size() const override { return target_.size(); }
  double value(const Eigen::VectorXd& x) override;
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override;
  /// The identity (the pull) plus the barrier's PSD-projected blocks.
  void hessian(const Eigen::VectorXd& x, HessianBlocks& H) override;
  double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) override;

 private:
  Eigen::VectorXd target_;
  ContactTerm& contact_;
  const Confinement& confinement_;
};

/// What one relaxation did.
struct RelaxationStats {
  int vertices = 0;    ///< vertices freed
  int iterations = 0;  ///< Newton iterations
  double seconds = 0.0;
};

/// Relaxes x (the level-(l+1) initializer of `fine`, intersection-free) toward `target` as
/// above, where `safe_gap` is g. x is unchanged when no vertex needs it.
RelaxationStats relax_toward_targets(const ShellSystem& fine, const Eigen::VectorXd& target,
                                     double safe_gap, Eigen::VectorXd& x);

/// Relaxes the vertices `freed` of any contact surface at x (intersection-free) toward `target`
/// by relax_free_vertices on their patch (relaxation_patch.hpp), the others held; κ as in
/// ContactTerm's constructor.
RelaxationStats relax_on_patch(const ContactSurface& surface, const ContactParameters& parameters,
                               std::optional<double> fixed_stiffness, double bbox_diagonal,
                               const std::vector<bool>& freed, const Positions& target,
                               double safe_gap, Positions& x);

/// Minimizes R over the DOFs `dofs` frees, from x (intersection-free), with κ balanced against
/// the pull at x and IPC's updates, then raised tenfold per round while a pair with a freed
/// vertex stays closer than g/2 (at most three times): the relaxation of relax_toward_targets on
/// any contact surface, such as a partly expanded level's between two batches (paper §4.4.4).
/// Steps are cut to keep the vertices inside `confinement`'s boxes.
RelaxationStats relax_free_vertices(ContactTerm& contact, const Eigen::VectorXd& target,
                                    const DofMap& dofs, double safe_gap, Eigen::VectorXd& x,
                                    const Confinement& confinement = {});

}  // namespace psq
