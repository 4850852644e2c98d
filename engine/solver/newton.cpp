#include "engine/solver/newton.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

namespace psq {
namespace {

/// Diagonal shifts tried when K is not positive definite: σ = 1e-8·s, 1e-7·s, …, 1·s with s
/// the mean diagonal of K, so the first shift barely perturbs a well-scaled system and the
/// last one turns d into a scaled gradient step.
constexpr double kFirstRelativeShift = 1e-8;
constexpr double kShiftGrowth = 10.0;
constexpr int kShiftAttempts = 9;

/// Shares β of ∇²E's negative curvature kept in P + β(∇²E − P) when ∇²E itself is indefinite
/// (project on demand): ½, ¼, ⅛, each a factorization; below ⅛ the blend is nearly P.
constexpr double kFirstBlend = 0.5;
constexpr double kLastBlend = 0.125;

/// A full step that lowers E by more than this fraction of the linear prediction −gᵀd (an exact
/// quadratic model predicts ½) met much less curvature than K promised: the projected Hessian
/// overestimates it where the energy is not convex (a sheet snapping through a twist), and full
/// steps are then short. Only such steps try longer ones.
constexpr double kExtrapolationTrigger = 0.75;
/// Longer steps tried after such a full step: α = 2, 4, … up to this.
constexpr double kMaxExtrapolation = 64.0;
/// Full steps predicted to lower E by less than this fraction of |E| are never extended: their
/// measured decrease is mostly rounding of E, and extending on it (α up to 64) throws a
/// converging solve off (a static cantilever at tolerance 1e-9 m stalled at 100 iterations).
constexpr double kExtrapolationFloor = 1e-9;

/// A failed line search whose step was predicted to lower E by less than this many times E's
/// measured rounding has stagnated at round-off: descent that small is lost in the rounding.
constexpr double kResolvableDecrease = 100.0;

/// Energy changes smaller than this fraction of |E| are below the rounding of E itself, so
/// the Armijo test does not reject a step for them (it would stall a converging solve).
constexpr double kEnergyRoundoff = 1e-12;

void check_settings(const NewtonSettings& s) {
  const auto require = [](bool ok, const char* name, double value, const char* range) {
    if (!ok)
      throw InputError(
          fmt::format("Newton setting {} = {} is out of range: it must be {}", name, value, range));
  };
  require(s.tolerance > 0.0 && std::isfinite(s.tolerance), "tolerance", s.tolerance, "> 0");
  require(s.step_scale > 0.0 && std::isfinite(s.step_scale), "step_scale", s.step_scale, "> 0");
  require(s.max_iterations >= 0, "max_iterations", s.max_iterations, ">= 0");
  require(s.armijo >= 0.0 && s.armijo < 1.0, "armijo", s.armijo, "in [0, 1)");
  require(s.backtracking > 0.0 && s.backtracking < 1.0, "backtracking", s.backtracking,
          "in (0, 1)");
  require(s.min_step > 0.0 && s.min_step <= 1.0, "min_step", s.min_step, "in (0, 1]");
  require(s.max_cut_steps >= 0, "max_cut_steps", s.max_cut_steps, ">= 0");
  require(s.cut_step > 0.0 && s.cut_step <= 1.0, "cut_step", s.cut_step, "in (0, 1]");
}

std::string dof_name(Eigen::Index dof) {
  return fmt::format("DOF {} (vertex {}, {})", dof, dof / 3, "xyz"[dof % 3]);
}

std::string where(int iteration) {
  return iteration == 0 ? std::string("at the initial point")
                        : fmt::format("at Newton iteration {}", iteration);
}

/// Fixed DOFs are ignored: their gradient entries never enter the system.
void check_gradient(const Eigen::VectorXd& gradient, const DofMap& dofs, int iteration) {
  for (Eigen::Index i = 0; i < gradient.size(); ++i)
    if (dofs.reduced(i) >= 0 && !std::isfinite(gradient[i]))
      throw NumericalError(
          fmt::format("gradient is {} at {} {}", gradient[i], dof_name(i), where(iteration)));
}

/// Mean |K_cc| of an upper-triangular CSC matrix (the diagonal closes each column), or 1 when
/// that is zero or not finite, so the shift has a scale even for a zero matrix.
double diagonal_scale(const Eigen::SparseMatrix<double>& upper) {
  if (upper.cols() == 0) return 1.0;
  double sum = 0.0;
  for (Eigen::Index c = 0; c < upper.cols(); ++c)
    sum += std::abs(upper.valuePtr()[upper.outerIndexPtr()[c + 1] - 1]);
  const double mean = sum / static_cast<double>(upper.cols());
  return mean > 0.0 && std::isfinite(mean) ? mean : 1.0;
}

}  // namespace

bool RoundoffStagnation::stagnated(double step_norm, double energy) {
  if (step_norm < kProgress * best_step_norm_) {
    best_step_norm_ = step_norm;
    start_window(energy);
    return false;
  }
  if (++iterations_in_window_ < kWindow) return false;
  if (energy_at_window_start_ - energy <= kWindow * kEnergyRoundoff * std::abs(energy))
    return true;
  start_window(energy);
  return false;
}

void RoundoffStagnation::start_window(double energy) {
  energy_at_window_start_ = energy;
  iterations_in_window_ = 0;
}

NewtonResult NewtonSolver::minimize(Objective& objective, Eigen::VectorXd& x, const DofMap& dofs,
                                    const NewtonSettings& settings, const Progress& progress,
                                    RoundoffStagnation* stagnation) {
  const auto start = std::chrono::steady_clock::now();
  check_settings(settings);
  if (objective.size() != x.size() || dofs.full_size() != x.size())
    throw std::invalid_argument(fmt::format("Newton: objective has {} unknowns, x {}, DofMap {}",
                                            objective.size(), x.size(), dofs.full_size()));
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]))
      throw NumericalError(fmt::format("initial position is {} at {}", x[i], dof_name(i)));

  NewtonResult result;
  hessian_.fixed_vertices = dofs.fixed_vertices();
  // Nothing left to take and nothing to judge: a capped step resumed after its last iteration
  // ends as the uninterrupted one did, without a gradient, Hessian or factorization.
  if (settings.max_iterations == 0 && !settings.judge_final_iterate) {
    result.energy = objective.value(x);
    return result;
  }
  NewtonIteration record;
  double energy = 0.0;
  {
    ScopedTimer timer(record.times.assembly);
    energy = objective.value(x);
  }
  if (!std::isfinite(energy))
    throw NumericalError(fmt::format("objective value is {} at the initial point", energy));

  Eigen::VectorXd gradient;
  Eigen::VectorXd free_gradient;
  RoundoffStagnation own_stagnation;
  RoundoffStagnation& watcher = stagnation != nullptr ? *stagnation : own_stagnation;
  int consecutive_cut_steps = 0;
  for (int k = 0;; ++k) {
    record.iteration = k;
    record.energy = energy;
    {
      ScopedTimer timer(record.times.assembly);
      objective.gradient(x, gradient);
      check_gradient(gradient, dofs, k);
      free_gradient = dofs.restrict(gradient);
    }
    record.gradient_norm = free_gradient.norm();
    Eigen::VectorXd free_direction = search_direction(objective, x, dofs, free_gradient,
                                                      settings.project_on_demand, record);
    record.step_norm = free_direction.lpNorm<Eigen::Infinity>() / settings.step_scale;
    // The tolerance is a bound on the projected Newton step (IPC's measure): ∇²E can be stiffer
    // than its projection where bent hinges add curvature, and its shorter step would pass the
    // test with more force left unbalanced. So a short unprojected step is judged projected.
    if (!record.projected() && record.step_norm < settings.tolerance) {
      free_direction = search_direction(objective, x, dofs, free_gradient, false, record);
      record.step_norm = free_direction.lpNorm<Eigen::Infinity>() / settings.step_scale;
    }
    const Eigen::VectorXd direction = dofs.extend(free_direction);

    // A gradient fallback step says nothing about the distance to the minimum.
    result.converged =
        record.direction != DirectionKind::gradient && record.step_norm < settings.tolerance;
    result.stagnated = !result.converged && watcher.stagnated(record.step_norm, energy);
    if (!result.converged && !result.stagnated && k < settings.max_iterations) {
      energy = line_search(objective, x, direction, energy, free_gradient.dot(free_direction),
                           settings, record);
      result.stagnated = record.below_energy_rounding;
    }

    result.history.push_back(record);
    result.times += record.times;
    if (progress) progress(record);
    if (result.converged || result.stagnated || k == settings.max_iterations) break;
    if (k + 1 == settings.max_iterations && !settings.judge_final_iterate) break;
    consecutive_cut_steps =
        record.feasible_step < settings.cut_step ? consecutive_cut_steps + 1 : 0;
    if (settings.max_cut_steps > 0 && consecutive_cut_steps >= settings.max_cut_steps) break;
    record = NewtonIteration{};
  }

  // A judged final iterate is a record without a step; an unjudged solve ends on a step.
  const NewtonIteration& last = result.history.back();
  result.iterations = last.step_length > 0.0 ? last.iteration + 1 : last.iteration;
  result.energy = energy;
  result.gradient_norm = last.gradient_norm;
  result.step_norm = last.step_norm;
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

bool NewtonSolver::assemble_hessian(Objective& objective, const Eigen::VectorXd& x,
                                    const DofMap& dofs, bool project, NewtonIteration& record) {
  bool pattern_changed = false;
  {
    ScopedTimer timer(record.times.assembly);
    hessian_.project = project;
    objective.hessian(x, hessian_);
    pattern_changed = assembler_.assemble(hessian_, dofs);
  }
  record.pattern_changed = record.pattern_changed || pattern_changed;
  if (pattern_changed || !cholmod_.analyzed()) {
    ScopedTimer timer(record.times.factorization);
    cholmod_.analyze(assembler_.matrix());
  }
  return pattern_changed;
}

Eigen::VectorXd NewtonSolver::search_direction(Objective& objective, const Eigen::VectorXd& x,
                                               const DofMap& dofs,
                                               const Eigen::VectorXd& free_gradient,
                                               bool try_unprojected, NewtonIteration& record) {
  // A stationary point (or nothing free to move): d = 0 exactly, no system to solve.
  if (free_gradient.isZero(0.0)) return Eigen::VectorXd::Zero(free_gradient.size());
  Eigen::VectorXd direction;
  record.direction = DirectionKind::newton;
  if (try_unprojected) {
    assemble_hessian(objective, x, dofs, false, record);
    record.kept_negative_curvature = 1.0;
    if (try_newton(assembler_.matrix(), 0.0, free_gradient, direction, record)) return direction;
    exact_ = assembler_.matrix();
  }
  record.kept_negative_curvature = 0.0;
  // The blends need ∇²E and P on one pattern, the one analyzed.
  const bool pattern_changed = assemble_hessian(objective, x, dofs, true, record);
  if (try_unprojected && !pattern_changed && try_blends(free_gradient, direction, record))
    return direction;
  if (try_newton(assembler_.matrix(), 0.0, free_gradient, direction, record)) return direction;

  record.direction = DirectionKind::shifted_newton;
  double shift = kFirstRelativeShift * diagonal_scale(assembler_.matrix());
  for (int attempt = 0; attempt < kShiftAttempts; ++attempt, shift *= kShiftGrowth) {
    record.shift = shift;
    if (try_newton(assembler_.matrix(), shift, free_gradient, direction, record))
      return direction;
  }
  record.direction = DirectionKind::gradient;
  record.shift = 0.0;
  return -free_gradient;
}

bool NewtonSolver::try_blends(const Eigen::VectorXd& free_gradient, Eigen::VectorXd& direction,
                              NewtonIteration& record) {
  const auto values = [](const Eigen::SparseMatrix<double>& m) {
    return Eigen::Map<const Eigen::ArrayXd>(m.valuePtr(), m.nonZeros());
  };
  const Eigen::SparseMatrix<double>& projected = assembler_.matrix();
  const Eigen::ArrayXd dropped_curvature = values(exact_) - values(projected);
  blended_ = projected;
  Eigen::Map<Eigen::ArrayXd> blended(blended_.valuePtr(), blended_.nonZeros());
  for (double beta = kFirstBlend; beta >= kLastBlend; beta *= 0.5) {
    blended = values(projected) + beta * dropped_curvature;
    if (try_newton(blended_, 0.0, free_gradient, direction, record)) {
      record.kept_negative_curvature = beta;
      return true;
    }
  }
  return false;
}

bool NewtonSolver::try_newton(const Eigen::SparseMatrix<double>& K, double shift,
                              const Eigen::VectorXd& free_gradient, Eigen::VectorXd& direction,
                              NewtonIteration& record) {
  try {
    ScopedTimer timer(record.times.factorization);
    cholmod_.factorize(K, shift);
  } catch (const NotPositiveDefiniteError&) {
    return false;
  } catch (const NumericalError& error) {
    throw NumericalError(fmt::format("Hessian {}: {}", where(record.iteration), error.what()));
  }
  ScopedTimer timer(record.times.solve);
  direction = cholmod_.solve(-free_gradient);
  return direction.allFinite() && free_gradient.dot(direction) < 0.0;
}

double NewtonSolver::line_search(Objective& objective, Eigen::VectorXd& x,
                                 const Eigen::VectorXd& direction, double energy, double slope,
                                 const NewtonSettings& settings, NewtonIteration& record) {
  ScopedTimer timer(record.times.line_search);
  const double feasible = objective.max_feasible_step(x, direction);
  if (std::isnan(feasible))
    throw NumericalError(fmt::format("max_feasible_step is nan {}", where(record.iteration)));
  record.feasible_step = std::min(1.0, feasible);

  const double slack = kEnergyRoundoff * std::abs(energy);
  // E at the smallest α whose point still differs from x: the model's change is negligible
  // there, so what E changed by is its own rounding.
  std::optional<double> smallest_move_energy;
  for (double alpha = record.feasible_step; alpha >= settings.min_step;
       alpha *= settings.backtracking) {
    trial_ = x + alpha * direction;
    const double trial_energy = objective.value(trial_);
    if (std::isfinite(trial_energy) && trial_ != x) smallest_move_energy = trial_energy;
    ++record.line_search_trials;
    const double bound = energy + settings.armijo * alpha * slope + slack;
    if (std::isfinite(trial_energy) && trial_energy <= bound) {
      record.step_length = alpha;
      const bool underestimated = alpha == 1.0 &&
                                  -slope > kExtrapolationFloor * std::abs(energy) &&
                                  trial_energy - energy < kExtrapolationTrigger * slope;
      const double accepted = underestimated
                                  ? extrapolate(objective, x, direction, trial_energy, record)
                                  : trial_energy;
      x.swap(trial_);
      return accepted;
    }
  }
  // A sum of large cancelling terms can round far above ε|E| (a plate 1e6 times stiffer than
  // the cloth on it). A step whose whole predicted decrease is below E's rounding cannot be
  // resolved, and neither can one whose trials, every one, rounded back to x; a step predicted
  // to gain far more that still finds no decrease is a failure.
  const bool resolvable =
      record.line_search_trials == 0 ||
      (smallest_move_energy.has_value() &&
       !(-slope * record.feasible_step <
         kResolvableDecrease * std::abs(*smallest_move_energy - energy)));
  if (!resolvable) {
    record.below_energy_rounding = true;
    return energy;
  }
  throw NumericalError(fmt::format(
      "line search failed at iteration {}, ‖g‖ = {:.6e} (first trial step {:.3e}, {} trials, "
      "E = {:.12e})",
      record.iteration, record.gradient_norm, record.feasible_step, record.line_search_trials,
      energy));
}

double NewtonSolver::extrapolate(Objective& objective, const Eigen::VectorXd& x,
                                 const Eigen::VectorXd& direction, double full_step_energy,
                                 NewtonIteration& record) {
  double accepted = full_step_energy;
  // One CCD query covers every longer step: the full step's check does not, and asking about
  // each α in turn would search the surface for each.
  const double longest =
      kMaxExtrapolation * objective.max_feasible_step(x, kMaxExtrapolation * direction);
  for (double alpha = 2.0; alpha <= longest; alpha *= 2.0) {
    longer_trial_ = x + alpha * direction;
    const double longer_energy = objective.value(longer_trial_);
    ++record.line_search_trials;
    if (!(std::isfinite(longer_energy) && longer_energy < accepted)) break;
    accepted = longer_energy;
    record.step_length = alpha;
    trial_.swap(longer_trial_);
  }
  return accepted;
}

NewtonSolver::Progress offset_progress(NewtonSolver::Progress progress, const int& offset) {
  if (!progress) return {};
  return [progress = std::move(progress), &offset](const NewtonIteration& it) {
    NewtonIteration shifted = it;
    shifted.iteration += offset;
    progress(shifted);
  };
}

}  // namespace psq
