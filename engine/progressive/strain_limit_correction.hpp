#pragma once
// Strain-limit feasibility of a refinement's initializer (paper §4.4.5, after PCS, Zhang et al.
// 2022): the level-(l+1) initializer (prolonged, or safely expanded with contact) may stretch
// some of its new triangles to or beyond a shell's strain limit s̄, where the level's barrier is
// undefined. The vertices level l already had stay where they are, and the vertices level l+1
// inserted move to minimize the stretch excess
//   V(x) = Σ_t Ā_t (σ₁(F_t) − s_c)₊² + ½ ρ ‖x − x₀‖²,   s_c = s̄ − kCorrectionTarget·δ,
// δ = s̄ − 1 the barrier's band, σ₁ the largest principal stretch, x₀ the initializer. σ₁ = ‖F‖₂
// is convex in F and F is affine in the positions, so V is convex: Newton with the Gauss–Newton
// Hessian 2Ā (∇σ₁)(∇σ₁)ᵀ (plus ρ, which keeps it definite along motions no excess constrains)
// finds its minimizer, whose excess is zero wherever a feasible placement of the new vertices
// exists. The solve stops as soon as every triangle is below s̄ − kCorrectionSlack·δ. With
// contact, the scene's barrier is added (κ from IPC's balance with V's gradient) and each step is
// cut by the contact CCD, so the correction never introduces an intersection. Where the new
// vertices alone cannot restore the limit (a triangle of old vertices only), every unpinned
// vertex is freed for a second solve. Each solve ends at the best state it passed (the tightest
// triangle is a maximum, which a step that lowers the sum may raise) and stops once that best
// state stops improving. A correction that ends short of s̄ − kCorrectionSlack·δ is still taken
// when every triangle is below s̄ − kFeasibleSlack·δ: strictly within the limit, the level's
// barrier is finite there and its solve takes over (the contact barrier pushing a sheet onto a
// sphere can hold the correction a few per mille of δ above the first bound).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "engine/elastic/deformation_gradient.hpp"
#include "engine/sim/contact_term.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/solver/objective.hpp"

namespace psq {

/// V above over the strain-limited shells of a system, measured from a start state x₀; with a
/// contact term, V plus its barrier (so that pairs near contact are held apart rather than
/// stopping every step at the CCD bound), with the contact CCD as the feasible step.
class StretchExcess final : public Objective {
 public:
  /// The tightest triangle of a state: its shell's name and limit and its σ₁.
  struct Tightest {
    std::string shell;      ///< empty when no shell is limited
    double limit = 0.0;     ///< s̄ of the shell
    double accepted = 0.0;  ///< s̄ − kCorrectionSlack·δ of the shell
    double sigma = 0.0;     ///< σ₁ of the triangle
    bool acceptable = true; ///< σ₁ ≤ s̄ − kCorrectionSlack·δ for every limited triangle
    /// σ₁ ≤ s̄ − kFeasibleSlack·δ for every limited triangle: strictly within the limits, the
    /// barrier finite, with less room than `acceptable` gives it.
    bool feasible = true;
    /// How far the tightest triangle is above its accepted bound (σ₁ − (s̄ − kCorrectionSlack·δ)):
    /// the measure a correction reduces.
    [[nodiscard]] double excess() const { return sigma - accepted; }
  };

  /// `contact` may be null (no barrier, no CCD) and must outlive this objective.
  StretchExcess(const ShellSystem& system, Eigen::VectorXd start, ContactTerm* contact);
  /// Adds the barrier and CCD of `contact` (null: removes them) from here on.
  void set_contact(ContactTerm* contact) { contact_ = contact; }

  [[nodiscard]] Eigen::Index size() const override { return start_.size(); }
  double value(const Eigen::VectorXd& x) override;
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override;
  /// ρ on the diagonal and the Gauss–Newton block 2Ā (A vec(u₁v₁ᵀ))(A vec(u₁v₁ᵀ))ᵀ of each
  /// triangle above s_c (PSD).
  void hessian(const Eigen::VectorXd& x, HessianBlocks& H) override;
  double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) override;

  /// ∇V without the contact barrier.
  void excess_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// The triangle of x closest to (or farthest beyond) its accepted stretch.
  [[nodiscard]] Tightest tightest(const Eigen::VectorXd& x) const;

 private:
  /// One strain-limited shell's triangles and stretches.
  struct LimitedShell {
    std::string name;
    TriangleElements triangles;
    double limit;     ///< s̄
    double target;    ///< s_c
    double accepted;  ///< s̄ − kCorrectionSlack·δ
  };

  std::vector<LimitedShell> shells_;
  Eigen::VectorXd start_;
  ContactTerm* contact_;
};

/// What one strain-limit correction did.
struct StrainCorrectionStats {
  int iterations = 0;              ///< Newton iterations, both solves
  double stretch_before = 0.0;     ///< largest σ₁ / s̄ of a limited triangle at the start
  double stretch_after = 0.0;      ///< the same at the end
  bool freed_old_vertices = false; ///< the second solve, over every unpinned vertex, ran
  double seconds = 0.0;
};

/// Moves the vertices marked in `inserted` (level-(l+1) vertex indices of `fine`, the level-
/// (l+1) system) so that every triangle of every strain-limited shell of x is strictly below
/// its limit with a margin, as above; x is left unchanged when it already is. `level` (l+1)
/// names the level in messages.
/// @throws NumericalError naming the level, shell and stretch when no feasible state is found.
StrainCorrectionStats correct_strain_limits(const ShellSystem& fine,
                                            const std::vector<bool>& inserted, int level,
                                            Eigen::VectorXd& x);

}  // namespace psq
