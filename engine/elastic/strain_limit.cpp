#include "engine/elastic/strain_limit.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/core/error.hpp"
#include "engine/core/log_barrier.hpp"
#include "engine/elastic/element_loop.hpp"

namespace psq {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// Relative gap σ₁ − σ₂ below which the flip eigenvalue is taken from g″ (see header).
constexpr double kRepeatedStretchGap = 1e-6;

/// Slack, as a fraction of the band width, under which Codim-IPC doubles κ_s.
constexpr double kTightSlack = 1e-4;

/// Triangles with σ₁ ≤ ŝ (1 + kActivityTolerance) are left out of the gradient and Hessian:
/// an unstretched triangle has σ₁ = 1 up to rounding. Near ŝ, g′ ≈ 3(1 − r)²/δ and
/// g″ ≈ 6(1 − r)/δ², so at 1 − r = 1e-12 ŝ/δ (2e-11 by default) the dropped slope is ~1e-21 and
/// the dropped curvature ~1e-10 of their scales 1/δ, 1/δ²: these blocks would only cost assembly.
constexpr double kActivityTolerance = 1e-12;

/// Bisection stops when the bracket of the feasible step is this narrow.
constexpr double kStepTolerance = 1e-12;

/// r = (s̄ − σ)/δ, the barrier's normalized distance to the limit.
double normalized_slack(double sigma, const StrainLimitBand& band) {
  return (band.limit - sigma) / band.width();
}

/// Full SVD of F: F = U diag(σ) Vᵀ with U 3×3 (its third column orthogonal to F's range).
struct StretchFrame {
  Eigen::Vector2d sigma;
  Eigen::Matrix3d u;
  Eigen::Matrix2d v;
};

StretchFrame stretch_frame(const DeformationGradient& F) {
  const Eigen::JacobiSVD<DeformationGradient> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return {svd.singularValues(), svd.matrixU(), svd.matrixV()};
}

void require_below_limit(double stretch, const StrainLimitBand& band) {
  if (!(stretch < band.limit))
    throw NumericalError(fmt::format(
        "strain limit: stretch {:.9g} at or beyond the limit {:.9g}, derivatives undefined",
        stretch, band.limit));
}

/// The band, or InputError unless 0 < ŝ < s̄ (finite).
const StrainLimitBand& checked_band(const StrainLimitBand& band) {
  if (!(band.band_start > 0 && band.limit > band.band_start && std::isfinite(band.limit)))
    throw InputError(fmt::format(
        "strain limit: limit {} and band start {} must satisfy 0 < band start < limit (set "
        "the strain limit above 1, e.g. 1.05)",
        band.limit, band.band_start));
  return band;
}

/// κ_s, or InputError unless it is positive and finite.
double checked_stiffness(double stiffness) {
  if (!(stiffness > 0 && std::isfinite(stiffness)))
    throw InputError(
        fmt::format("strain limit: stiffness κ_s = {} must be positive and finite", stiffness));
  return stiffness;
}

/// σ₁ of the triangle at x.
double largest_stretch(const TrianglePositions& x, const MembraneRest& rest) {
  return principal_stretches(deformation_gradient(x, rest))[0];
}

/// σ₁ of the triangle at x + α dx, formed exactly as a line search forms its trial state.
double largest_stretch_along(const TrianglePositions& x, const TrianglePositions& dx,
                             const MembraneRest& rest, double alpha) {
  const TrianglePositions trial = x + alpha * dx;
  return largest_stretch(trial, rest);
}

/// Throws NumericalError unless the triangle at x is below the limit.
void require_feasible_start(const TrianglePositions& x, const MembraneRest& rest, double limit) {
  const double start = largest_stretch(x, rest);
  if (!(start < limit))
    throw NumericalError(fmt::format(
        "strain limit: the line search starts at stretch {:.9g}, not below the limit {:.9g}", start,
        limit));
}

/// The largest α ∈ [0, upper] with σ₁(x + α dx) < limit (strain_limit_feasible_step).
double feasible_step_up_to(const TrianglePositions& x, const TrianglePositions& dx,
                           const MembraneRest& rest, double limit, double upper) {
  require_feasible_start(x, rest, limit);
  if (largest_stretch_along(x, dx, rest, upper) < limit) return upper;
  double feasible = 0;
  double infeasible = upper;
  while (infeasible - feasible > kStepTolerance) {
    const double mid = 0.5 * (feasible + infeasible);
    (largest_stretch_along(x, dx, rest, mid) < limit ? feasible : infeasible) = mid;
  }
  return feasible;
}

}  // namespace

Eigen::Vector2d principal_stretches(const DeformationGradient& F) {
  return Eigen::JacobiSVD<DeformationGradient>(F).singularValues();
}

double strain_limit_barrier(double sigma, const StrainLimitBand& band) {
  return barrier(normalized_slack(sigma, band), 1);
}

double strain_limit_barrier_first_derivative(double sigma, const StrainLimitBand& band) {
  // dr/dσ = −1/δ.
  return -barrier_first_derivative(normalized_slack(sigma, band), 1) / band.width();
}

double strain_limit_barrier_second_derivative(double sigma, const StrainLimitBand& band) {
  return barrier_second_derivative(normalized_slack(sigma, band), 1) /
         (band.width() * band.width());
}

double strain_limit_density(const DeformationGradient& F, const StrainLimitBand& band) {
  const Eigen::Vector2d sigma = principal_stretches(F);
  return strain_limit_barrier(sigma[0], band) + strain_limit_barrier(sigma[1], band);
}

DeformationGradient strain_limit_stress(const DeformationGradient& F, const StrainLimitBand& band) {
  const StretchFrame frame = stretch_frame(F);
  require_below_limit(frame.sigma[0], band);
  DeformationGradient stress = DeformationGradient::Zero();
  for (int k = 0; k < 2; ++k)
    stress += strain_limit_barrier_first_derivative(frame.sigma[k], band) * frame.u.col(k) *
              frame.v.col(k).transpose();
  return stress;
}

DeformationGradientMatrix strain_limit_stress_derivative(const DeformationGradient& F,
                                                         const StrainLimitBand& band,
                                                         bool project_psd) {
  const StretchFrame frame = stretch_frame(F);
  require_below_limit(frame.sigma[0], band);
  const Eigen::Vector2d& sigma = frame.sigma;
  const Eigen::Vector3d u1 = frame.u.col(0);
  const Eigen::Vector3d u2 = frame.u.col(1);
  const Eigen::Vector3d n = frame.u.col(2);
  const Eigen::Vector2d v1 = frame.v.col(0);
  const Eigen::Vector2d v2 = frame.v.col(1);
  const Eigen::Vector2d slope(strain_limit_barrier_first_derivative(sigma[0], band),
                              strain_limit_barrier_first_derivative(sigma[1], band));
  const Eigen::Vector2d curvature(strain_limit_barrier_second_derivative(sigma[0], band),
                                  strain_limit_barrier_second_derivative(sigma[1], band));

  DeformationGradientMatrix h = DeformationGradientMatrix::Zero();
  const auto add_mode = [&](double eigenvalue, const DeformationGradientVector& mode) {
    if (eigenvalue == 0 || (project_psd && eigenvalue < 0)) return;
    h.noalias() += eigenvalue * mode * mode.transpose();
  };
  add_mode(curvature[0], vec_outer(u1, v1));
  add_mode(curvature[1], vec_outer(u2, v2));
  const double inv_sqrt2 = 1.0 / std::sqrt(2.0);
  // slope is zero unless σ is inside the band, where σ > ŝ > 0: the quotients below only
  // divide by stretches that are bounded away from zero.
  if (slope[0] + slope[1] > 0)
    add_mode((slope[0] + slope[1]) / (sigma[0] + sigma[1]),
             inv_sqrt2 * (vec_outer(u1, v2) - vec_outer(u2, v1)));
  const bool repeated = sigma[0] - sigma[1] <= kRepeatedStretchGap * sigma[0];
  add_mode(repeated ? 0.5 * (curvature[0] + curvature[1])
                    : (slope[0] - slope[1]) / (sigma[0] - sigma[1]),
           inv_sqrt2 * (vec_outer(u1, v2) + vec_outer(u2, v1)));
  for (int k = 0; k < 2; ++k)
    if (slope[k] > 0) add_mode(slope[k] / sigma[k], vec_outer(n, frame.v.col(k)));
  return h;
}

double strain_limit_triangle_energy(const TrianglePositions& x, const MembraneRest& rest,
                                    const StrainLimitBand& band, double stiffness) {
  return stiffness * rest.area * strain_limit_density(deformation_gradient(x, rest), band);
}

TriangleVector strain_limit_triangle_gradient(const TrianglePositions& x, const MembraneRest& rest,
                                              const StrainLimitBand& band, double stiffness) {
  return pull_back_stress(strain_limit_stress(deformation_gradient(x, rest), band), rest,
                          stiffness * rest.area);
}

TriangleMatrix strain_limit_triangle_hessian(const TrianglePositions& x, const MembraneRest& rest,
                                             const StrainLimitBand& band, double stiffness,
                                             bool project_psd) {
  return pull_back_stress_derivative(
      strain_limit_stress_derivative(deformation_gradient(x, rest), band, project_psd), rest,
      stiffness * rest.area);
}

double strain_limit_feasible_step(const TrianglePositions& x, const TrianglePositions& dx,
                                  const MembraneRest& rest, double limit) {
  return feasible_step_up_to(x, dx, rest, limit, 1);
}

double initial_strain_limit_stiffness(double stretch_modulus, const StrainLimitBand& band) {
  return stretch_modulus * band.width() * band.width();
}

double update_strain_limit_stiffness(double stiffness, double previous_min_slack, double min_slack,
                                     const StrainLimitBand& band, double max_stiffness) {
  const double tight = kTightSlack * band.width();
  if (previous_min_slack < tight && min_slack < tight)
    return std::min(2 * stiffness, max_stiffness);
  return stiffness;
}

StrainLimitEnergy::StrainLimitEnergy(const TriMesh& rest, const StrainLimitBand& band,
                                     double stiffness, int vertex_offset)
    : band_(checked_band(band)),
      stiffness_(checked_stiffness(stiffness)),
      vertex_offset_(vertex_offset),
      vertex_count_(rest.vertex_count()),
      triangles_(rest, vertex_offset, "strain limit") {}

void StrainLimitEnergy::set_stiffness(double stiffness) {
  stiffness_ = checked_stiffness(stiffness);
}

void StrainLimitEnergy::check(const Eigen::VectorXd& x) const {
  check_positions(x, vertex_offset_, vertex_count_, "strain limit");
}

StrainLimitEnergy::ActiveSet StrainLimitEnergy::active_set(const Eigen::VectorXd& x) const {
  std::vector<char> active(triangles_.size());
  parallel_for_elements(triangles_.size(), [&](std::size_t t) {
    active[t] = largest_stretch(triangles_.positions(x, t), triangles_.rest(t)) >
                band_.band_start * (1 + kActivityTolerance);
  });
  ActiveSet set;
  for (std::size_t t = 0; t < active.size(); ++t) {
    if (!active[t]) continue;
    set.triangles.push_back(t);
    const auto stencil = triangles_.stencils().begin() + 3 * t;
    set.stencils.insert(set.stencils.end(), stencil, stencil + 3);
  }
  return set;
}

double StrainLimitEnergy::value(const Eigen::VectorXd& x) const {
  check(x);
  return parallel_element_sum(triangles_.size(), [&](std::size_t t) {
    return strain_limit_triangle_energy(triangles_.positions(x, t), triangles_.rest(t), band_,
                                        stiffness_);
  });
}

void StrainLimitEnergy::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  check(x);
  const ActiveSet active = active_set(x);
  add_element_gradients<3>(
      active.stencils,
      [&](std::size_t e) {
        const std::size_t t = active.triangles[e];
        return strain_limit_triangle_gradient(triangles_.positions(x, t), triangles_.rest(t), band_,
                                              stiffness_);
      },
      g);
}

void StrainLimitEnergy::hessian(const Eigen::VectorXd& x, ElementMatrices& out,
                                bool project_psd) const {
  check(x);
  const ActiveSet active = active_set(x);
  fill_element_hessians<3>(
      active.stencils,
      [&](std::size_t e) {
        const std::size_t t = active.triangles[e];
        return strain_limit_triangle_hessian(triangles_.positions(x, t), triangles_.rest(t), band_,
                                             stiffness_, project_psd);
      },
      out);
}

double StrainLimitEnergy::max_feasible_step(const Eigen::VectorXd& x,
                                            const Eigen::VectorXd& dx) const {
  check(x);
  check_positions(dx, vertex_offset_, vertex_count_, "strain limit step");
  // σ₁ is convex along the line: a triangle below the limit at both ends of [0, 1] is below
  // it all along and cannot bound the step. Only the others are bisected, each up to the
  // bound found so far (a triangle below the limit at that bound returns it at once).
  std::vector<char> crosses(triangles_.size());
  parallel_for_elements(triangles_.size(), [&](std::size_t t) {
    const TrianglePositions corners = triangles_.positions(x, t);
    require_feasible_start(corners, triangles_.rest(t), band_.limit);
    crosses[t] = largest_stretch_along(corners, triangles_.positions(dx, t), triangles_.rest(t),
                                       1) >= band_.limit;
  });
  double step = 1;
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    if (crosses[t])
      step = feasible_step_up_to(triangles_.positions(x, t), triangles_.positions(dx, t),
                                 triangles_.rest(t), band_.limit, step);
  return step;
}

double StrainLimitEnergy::min_slack(const Eigen::VectorXd& x) const {
  check(x);
  double slack = kInfinity;
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    slack = std::min(slack,
                     band_.limit - largest_stretch(triangles_.positions(x, t), triangles_.rest(t)));
  return slack;
}

}  // namespace psq
