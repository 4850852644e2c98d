#include "engine/elastic/strain_limit.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/core/error.hpp"
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

/// vec(a bᵀ) for a 3×2 matrix stored column by column.
Eigen::Matrix<double, 6, 1> vec_outer(const Eigen::Vector3d& a, const Eigen::Vector2d& b) {
  Eigen::Matrix<double, 6, 1> v;
  v << b[0] * a, b[1] * a;
  return v;
}

/// ∂vec(F)/∂(x0, x1, x2): block (k, i) is β_i[k]·I, β1, β2 the rows of D⁻¹, β0 = −β1 − β2.
Eigen::Matrix<double, 6, 9> deformation_gradient_jacobian(const MembraneRest& rest) {
  const Eigen::Vector2d beta1 = rest.rest_frame_inverse.row(0).transpose();
  const Eigen::Vector2d beta2 = rest.rest_frame_inverse.row(1).transpose();
  const Eigen::Vector2d beta[3] = {-beta1 - beta2, beta1, beta2};
  Eigen::Matrix<double, 6, 9> a = Eigen::Matrix<double, 6, 9>::Zero();
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 2; ++k) a.block<3, 3>(3 * k, 3 * i).diagonal().setConstant(beta[i][k]);
  return a;
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
  const double r = normalized_slack(sigma, band);
  if (r <= 0) return kInfinity;
  if (r >= 1) return 0;
  return -(r - 1) * (r - 1) * std::log(r);
}

double strain_limit_barrier_first_derivative(double sigma, const StrainLimitBand& band) {
  const double r = normalized_slack(sigma, band);
  if (r <= 0) return kInfinity;
  if (r >= 1) return 0;
  return -(1 - r) * (2 * std::log(r) + 1 - 1 / r) / band.width();
}

double strain_limit_barrier_second_derivative(double sigma, const StrainLimitBand& band) {
  const double r = normalized_slack(sigma, band);
  if (r <= 0) return kInfinity;
  if (r >= 1) return 0;
  const double inverse = 1 / r;
  return (-2 * std::log(r) + inverse * (inverse + 2) - 3) / (band.width() * band.width());
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
  const auto add_mode = [&](double eigenvalue, const Eigen::Matrix<double, 6, 1>& mode) {
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
  const DeformationGradient stress = strain_limit_stress(deformation_gradient(x, rest), band);
  const Eigen::Matrix<double, 6, 1> stress_vec = stress.reshaped();
  return stiffness * rest.area * deformation_gradient_jacobian(rest).transpose() * stress_vec;
}

TriangleMatrix strain_limit_triangle_hessian(const TrianglePositions& x, const MembraneRest& rest,
                                             const StrainLimitBand& band, double stiffness,
                                             bool project_psd) {
  const Eigen::Matrix<double, 6, 9> a = deformation_gradient_jacobian(rest);
  const DeformationGradientMatrix h_f =
      strain_limit_stress_derivative(deformation_gradient(x, rest), band, project_psd);
  return stiffness * rest.area * a.transpose() * h_f * a;
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
    : band_(band), vertex_offset_(vertex_offset), vertex_count_(rest.vertex_count()) {
  if (!(band.band_start > 0 && band.limit > band.band_start && std::isfinite(band.limit)))
    throw InputError(fmt::format(
        "strain limit: limit {} and band start {} must satisfy 0 < band start < limit (set "
        "the strain limit above 1, e.g. 1.05)",
        band.limit, band.band_start));
  set_stiffness(stiffness);
  const int n = rest.triangle_count();
  stencils_.reserve(3 * static_cast<std::size_t>(n));
  rest_.reserve(n);
  for (int t = 0; t < n; ++t) {
    TrianglePositions corners;
    for (int a = 0; a < 3; ++a) {
      corners.col(a) = rest.vertices.row(rest.triangles(t, a)).transpose();
      stencils_.push_back(vertex_offset + rest.triangles(t, a));
    }
    rest_.push_back(membrane_rest(corners));
    if (!(rest_.back().area > 0))
      throw InputError(
          fmt::format("strain limit: rest triangle {} (vertices {}, {}, {}) has zero area", t,
                      rest.triangles(t, 0), rest.triangles(t, 1), rest.triangles(t, 2)));
  }
}

void StrainLimitEnergy::set_stiffness(double stiffness) {
  if (!(stiffness > 0 && std::isfinite(stiffness)))
    throw InputError(
        fmt::format("strain limit: stiffness κ_s = {} must be positive and finite", stiffness));
  stiffness_ = stiffness;
}

TrianglePositions StrainLimitEnergy::positions(const Eigen::VectorXd& x, std::size_t t) const {
  TrianglePositions corners;
  for (int a = 0; a < 3; ++a) corners.col(a) = x.segment<3>(3 * stencils_[3 * t + a]);
  return corners;
}

void StrainLimitEnergy::check(const Eigen::VectorXd& x) const {
  check_positions(x, vertex_offset_, vertex_count_, "strain limit");
}

StrainLimitEnergy::ActiveSet StrainLimitEnergy::active_set(const Eigen::VectorXd& x) const {
  std::vector<char> active(rest_.size());
  parallel_for_elements(rest_.size(), [&](std::size_t t) {
    active[t] =
        largest_stretch(positions(x, t), rest_[t]) > band_.band_start * (1 + kActivityTolerance);
  });
  ActiveSet set;
  for (std::size_t t = 0; t < active.size(); ++t) {
    if (!active[t]) continue;
    set.triangles.push_back(t);
    set.stencils.insert(set.stencils.end(), stencils_.begin() + 3 * t,
                        stencils_.begin() + 3 * t + 3);
  }
  return set;
}

double StrainLimitEnergy::value(const Eigen::VectorXd& x) const {
  check(x);
  return parallel_element_sum(rest_.size(), [&](std::size_t t) {
    return strain_limit_triangle_energy(positions(x, t), rest_[t], band_, stiffness_);
  });
}

void StrainLimitEnergy::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  check(x);
  const ActiveSet active = active_set(x);
  add_element_gradients<3>(
      active.stencils,
      [&](std::size_t e) {
        const std::size_t t = active.triangles[e];
        return strain_limit_triangle_gradient(positions(x, t), rest_[t], band_, stiffness_);
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
        return strain_limit_triangle_hessian(positions(x, t), rest_[t], band_, stiffness_,
                                             project_psd);
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
  std::vector<char> crosses(rest_.size());
  parallel_for_elements(rest_.size(), [&](std::size_t t) {
    const TrianglePositions corners = positions(x, t);
    require_feasible_start(corners, rest_[t], band_.limit);
    crosses[t] = largest_stretch_along(corners, positions(dx, t), rest_[t], 1) >= band_.limit;
  });
  double step = 1;
  for (std::size_t t = 0; t < rest_.size(); ++t)
    if (crosses[t])
      step = feasible_step_up_to(positions(x, t), positions(dx, t), rest_[t], band_.limit, step);
  return step;
}

double StrainLimitEnergy::min_slack(const Eigen::VectorXd& x) const {
  check(x);
  double slack = kInfinity;
  for (std::size_t t = 0; t < rest_.size(); ++t)
    slack = std::min(slack, band_.limit - largest_stretch(positions(x, t), rest_[t]));
  return slack;
}

}  // namespace psq
