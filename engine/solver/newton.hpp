#pragma once
// Projected Newton with a backtracking line search (DESIGN.md §4), the minimizer of every
// incremental potential. A NewtonSolver keeps the sparse pattern, scatter map and CHOLMOD
// analysis between calls, because quasistatic stepping calls it every frame with the same
// stencils.

#include <functional>
#include <limits>

#include "engine/solver/cholmod_solver.hpp"
#include "engine/solver/dof_map.hpp"
#include "engine/solver/objective.hpp"
#include "engine/solver/solver_stats.hpp"
#include "engine/solver/sparse_assembler.hpp"

namespace psq {

struct NewtonSettings {
  /// Converged when ‖d‖∞ / step_scale < tolerance for the full Newton step d (IPC's test: a
  /// velocity-like measure when step_scale = Δt).
  double tolerance = 1e-5;
  double step_scale = 1.0;    ///< Δt of the incremental potential, set by the caller
  int max_iterations = 100;   ///< Newton steps before giving up (result.converged = false)
  double armijo = 1e-4;       ///< c in E(x + αd) ≤ E(x) + c·α·gᵀd
  double backtracking = 0.5;  ///< α ← backtracking·α after a rejected trial
  double min_step = 1e-12;    ///< the line search fails once α drops below this (≈ 40 halvings)
  /// false: after the max_iterations-th step the solve ends without evaluating the final
  /// iterate (no gradient, Hessian or factorization there), so it reports converged = false
  /// without knowing. For steps capped by design whose convergence nobody asks (progressive
  /// previews: settling decides when a level is done): at a cap of 2 it saves one of a step's
  /// three gradient–Hessian–factorization rounds (Newton.CappedSolve… counts the gradients).
  /// With max_iterations = 0 (a capped step resumed after its last iteration) such a solve
  /// does nothing and returns an empty history.
  bool judge_final_iterate = true;
  /// > 0: the solve returns, unconverged, after this many consecutive steps whose feasible
  /// step bound (Objective::max_feasible_step) was below `cut_step`. Such steps creep toward a
  /// constraint the objective holds too weakly; a caller that can stiffen it (the contact
  /// barrier's κ) gets control back at once instead of after its whole iteration budget.
  int max_cut_steps = 0;
  double cut_step = 0.1;  ///< the feasible step below which a step counts as cut
  /// Project-on-demand Newton (Longva et al. 2023, "Pitfalls of Projection"): each direction
  /// is first solved with ∇²E itself (HessianBlocks::project = false). Where that is not
  /// positive definite, with the first positive definite P + β(∇²E − P), β = ½, ¼, ⅛, of it and
  /// its element-wise PSD projection P, and only when none is with P: where a few elements
  /// make ∇²E indefinite, P drops the negative curvature of every element, and the blend keeps
  /// part of it. The projection overstates the
  /// curvature of compressed membranes, bent hinges and contact pairs, so projected Newton
  /// crawls through flat valleys in short steps (docs/benchmarks.md). Convergence is still
  /// judged on the projected step, so the tolerance means what it means without. Off by
  /// default: the equilibria it settles in can differ where a scene has several (a hanging
  /// drape), and it leaves stiff modes less over-solved (docs/scene-format.md).
  bool project_on_demand = false;
};

/// Watches a solve for stagnation at round-off (NewtonResult::stagnated): the step norm stops
/// falling while the energy changes only by its rounding. A slow solve that still lowers E
/// (backtracking through a fold, contact) is not stagnating, however long its step norms wander.
/// E is judged per window of iterations, not since the best step norm: one real drop of E (a
/// late snap) must not hide the rounding-level changes that follow it.
/// Nor is a solve stagnating whose step norm still falls steadily: a Newton matrix stiffer than
/// ∇²E (element-wise PSD projection where the assembled ∇²E is positive) converges linearly, and
/// near the minimum its energy changes drop below E's rounding long before its steps reach
/// round-off (the drape at Δt = 1e-3 s: step norms falling 5 % per iteration, docs/stress.md).
/// A caller that splits one solve into several minimize calls (FrameSolver's chunks between κ
/// updates, shorter than the window) passes one watcher to all of them.
class RoundoffStagnation {
 public:
  /// Iterations without the step norm falling to kProgress of its best, and without E falling
  /// beyond its rounding, before a solve has stagnated.
  static constexpr int kWindow = 10;
  /// A step norm below this fraction of the best so far is progress: a linear rate ρ counts as
  /// converging when ρ^k < kProgress for some k ≤ kWindow (ρ up to about 0.99), where a step norm
  /// at round-off wanders without setting such lows for long.
  static constexpr double kProgress = 0.9;

  /// Takes an iteration's step norm and its starting energy; true once stagnated.
  bool stagnated(double step_norm, double energy);

 private:
  void start_window(double energy);

  double best_step_norm_ = std::numeric_limits<double>::infinity();
  double energy_at_window_start_ = 0.0;
  int iterations_in_window_ = 0;
};

/// Minimizes an Objective over the free DOFs of a DofMap. Each iteration: gradient, projected
/// Hessian blocks, sparse assembly, Cholesky, direction d = −K⁻¹g (with a diagonal shift, then
/// the negative gradient, as fallbacks when K is not positive definite or d is not a descent
/// direction), first trial step α = min(1, max_feasible_step(x, d)), Armijo backtracking; a
/// full step that lowers E far more than the quadratic model predicts is extended (α = 2, 4, …)
/// while E keeps decreasing and the CCD allows the motion. A solve that stagnates at round-off
/// (NewtonResult::stagnated) stops instead of spending its remaining iterations.
class NewtonSolver {
 public:
  using Progress = std::function<void(const NewtonIteration&)>;

  /// Minimizes `objective` starting from x (size 3n), overwriting x with the last accepted
  /// iterate. Fixed DOFs of `dofs` keep their values exactly. `progress` is called once per
  /// record appended to the history.
  /// @throws NumericalError when x, E(x) or ∇E(x) is not finite at the start (naming which),
  ///   when the gradient or Hessian becomes non-finite, or when the line search cannot
  ///   decrease E above min_step.
  /// @throws InputError when a setting is out of range (naming it).
  /// `stagnation`: the watcher to continue (one solve split over several calls); a fresh one
  /// when null.
  NewtonResult minimize(Objective& objective, Eigen::VectorXd& x, const DofMap& dofs,
                        const NewtonSettings& settings, const Progress& progress = {},
                        RoundoffStagnation* stagnation = nullptr);

 private:
  /// Hessian, assembly, factorization and solve, with the fallbacks; returns d over the free
  /// DOFs and records how it was obtained.
  Eigen::VectorXd search_direction(Objective& objective, const Eigen::VectorXd& x,
                                   const DofMap& dofs, const Eigen::VectorXd& free_gradient,
                                   bool try_unprojected, NewtonIteration& record);
  /// Asks the objective for its Hessian (projected or not), assembles it over the free DOFs
  /// and analyzes its pattern when that changed; returns whether it did.
  bool assemble_hessian(Objective& objective, const Eigen::VectorXd& x, const DofMap& dofs,
                        bool project, NewtonIteration& record);
  /// Factorizes K + shift·I and solves for d; false when that matrix is not positive definite
  /// or d is not a descent direction (gᵀd ≥ 0).
  bool try_newton(const Eigen::SparseMatrix<double>& K, double shift,
                  const Eigen::VectorXd& free_gradient, Eigen::VectorXd& direction,
                  NewtonIteration& record);
  /// With ∇²E in exact_ and P in the assembler, on one pattern: d from the first positive
  /// definite P + β(∇²E − P), β = ½, ¼, ⅛; false when none is.
  bool try_blends(const Eigen::VectorXd& free_gradient, Eigen::VectorXd& direction,
                  NewtonIteration& record);
  /// Backtracking Armijo line search from α = min(1, max_feasible_step); moves x to the
  /// accepted point and returns its energy. Where no α decreases E and the step's predicted
  /// decrease is below the rounding of E itself (measured at the smallest α tried), x stays and
  /// record.below_energy_rounding is set: the solve has stagnated at round-off.
  double line_search(Objective& objective, Eigen::VectorXd& x, const Eigen::VectorXd& direction,
                     double energy, double slope, const NewtonSettings& settings,
                     NewtonIteration& record);

  /// After an accepted full step whose energy drop shows K overestimating the curvature: tries
  /// α = 2, 4, … (up to 64) along d while the CCD finds the whole motion from x safe
  /// and E keeps decreasing, leaving the best point in trial_ (which holds x + d on entry) and
  /// its α in record.step_length; returns its energy.
  double extrapolate(Objective& objective, const Eigen::VectorXd& x,
                     const Eigen::VectorXd& direction, double full_step_energy,
                     NewtonIteration& record);

  HessianBlocks hessian_;
  SparseAssembler assembler_;
  CholmodSolver cholmod_;
  Eigen::SparseMatrix<double> exact_;    ///< ∇²E over the free DOFs, kept for the blends
  Eigen::SparseMatrix<double> blended_;  ///< P + β(∇²E − P)
  Eigen::VectorXd trial_;
  Eigen::VectorXd longer_trial_;
};

/// `progress` with every iteration number shifted by `offset` (read at each call, so it may
/// grow between calls): a solve that continues earlier iterations numbers its own after them.
/// Empty when `progress` is.
NewtonSolver::Progress offset_progress(NewtonSolver::Progress progress, const int& offset);

}  // namespace psq
