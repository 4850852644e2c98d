#pragma once
// What a Newton solve reports: one record per iteration and totals, so callers can plot
// convergence and see where the time goes. The engine never prints; callers display these.

#include <chrono>
#include <vector>

namespace psq {

/// Wall-clock seconds spent in each phase of a Newton iteration.
struct PhaseTimes {
  /// Objective gradient and Hessian blocks (and the initial value) plus the scatter.
  double assembly = 0.0;
  double factorization = 0.0;  ///< CHOLMOD symbolic analysis (when the pattern changed) + numeric
  double solve = 0.0;          ///< triangular solves for the search direction
  double line_search = 0.0;    ///< feasible-step query and every objective value in the line search

  [[nodiscard]] double total() const { return assembly + factorization + solve + line_search; }
  PhaseTimes& operator+=(const PhaseTimes& other) {
    assembly += other.assembly;
    factorization += other.factorization;
    solve += other.solve;
    line_search += other.line_search;
    return *this;
  }
};

/// How the search direction of an iteration was obtained.
enum class DirectionKind {
  newton,          ///< d = −K⁻¹g with K = ∇²E or its projection (NewtonIteration::projected)
  shifted_newton,  ///< d = −(K + σI)⁻¹g: K was not positive definite or d was not descent
  gradient,        ///< d = −g: every shift failed too
};

/// One Newton iteration. The last record of a solve is the convergence check: it carries the
/// final energy, gradient norm and step norm, and takes no step (step_length = 0) — unless the
/// final iterate was not judged (NewtonSettings::judge_final_iterate), when it is the last step.
struct NewtonIteration {
  int iteration = 0;
  double energy = 0.0;         ///< E(x) at the start of the iteration
  double gradient_norm = 0.0;  ///< ‖∇E(x)‖₂ over the free DOFs
  double step_norm = 0.0;      ///< ‖d‖∞ / step_scale for the full direction d
  /// Accepted α: 0 when no step was taken, above 1 when a full step was extended.
  double step_length = 0.0;
  double feasible_step = 0.0;  ///< first trial α = min(1, max_feasible_step(x, d))
  int line_search_trials = 0;  ///< objective values evaluated by the line search
  DirectionKind direction = DirectionKind::newton;
  double shift = 0.0;            ///< σ when direction == shifted_newton
  bool pattern_changed = false;  ///< the sparsity pattern changed, so it was re-analyzed
  /// β of the matrix P + β(∇²E − P) that gave d: 1 for ∇²E itself, 0 for the element-wise
  /// PSD projection P, ½, ¼ or ⅛ where ∇²E was indefinite but keeping that share of its negative
  /// curvature was not (NewtonSettings::project_on_demand).
  double kept_negative_curvature = 0.0;
  /// d came from P alone, none of ∇²E's negative curvature kept.
  [[nodiscard]] bool projected() const { return kept_negative_curvature == 0.0; }
  /// The line search found no decrease of E, and the step's predicted decrease was below the
  /// rounding of E: no step was taken, and the solve stagnated at round-off.
  bool below_energy_rounding = false;
  PhaseTimes times;
};

/// Outcome of NewtonSolver::minimize. `converged == false` means max_iterations steps were
/// taken without meeting the tolerance; the caller decides what that means.
struct NewtonResult {
  bool converged = false;
  /// Stopped before converging because the solve stagnated at round-off: for
  /// RoundoffStagnation::kWindow iterations the step norm made no progress while E decreased by
  /// no more than its rounding, or a line search found no decrease below E's rounding
  /// (NewtonIteration::below_energy_rounding). The tolerance is then finer than double precision
  /// resolves for this problem, and step_norm is the accuracy reached.
  bool stagnated = false;
  /// Steps taken: history.size() − 1, or history.size() when the final iterate was not judged
  /// (NewtonSettings::judge_final_iterate): then the last record is the last step's.
  int iterations = 0;
  double energy = 0.0;         ///< final E(x)
  double gradient_norm = 0.0;  ///< ‖∇E‖₂ over the free DOFs at the last judged iterate
  double step_norm = 0.0;      ///< ‖d‖∞ / step_scale at the last judged iterate
  PhaseTimes times;            ///< sum of the per-iteration times
  double wall_seconds = 0.0;   ///< the whole call, ≥ times.total()
  std::vector<NewtonIteration> history;
};

/// Adds the seconds between construction and destruction to `sink`.
class ScopedTimer {
 public:
  explicit ScopedTimer(double& sink) : sink_(sink), start_(std::chrono::steady_clock::now()) {}
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;
  ~ScopedTimer() {
    sink_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  double& sink_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace psq
