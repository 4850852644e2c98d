#include "engine/contact/barrier.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/core/error.hpp"

namespace psq {
namespace {

/// Gap of IPC's κ_min estimate, as a fraction of the bounding-box diagonal.
constexpr double kStiffnessProbeGap = 1e-8;

/// κ_max / κ_min (IPC's choice).
constexpr double kStiffnessRange = 100;

bool positive_finite(double x) { return x > 0 && std::isfinite(x); }

}  // namespace

StencilDerivatives<12> barrier_of_distance(const StencilDerivatives<12>& distance,
                                           const BarrierBand& band) {
  const double s = band.barrier_argument(distance.value);
  if (!(s > 0))
    throw NumericalError(
        fmt::format("contact barrier: derivatives requested at squared distance {:.6g}, within the "
                    "thickness (ξ² = {:.6g})",
                    distance.value, band.thickness * band.thickness));
  const double s_hat = band.barrier_activation();
  return chain_rule(barrier(s, s_hat), barrier_first_derivative(s, s_hat),
                    barrier_second_derivative(s, s_hat), distance);
}

BarrierStiffness initial_barrier_stiffness(double bbox_diagonal, const BarrierBand& band,
                                           double average_mass,
                                           const Eigen::VectorXd& energy_gradient,
                                           const Eigen::VectorXd& barrier_gradient,
                                           double min_stiffness_scale) {
  if (!positive_finite(bbox_diagonal) || !positive_finite(band.activation_distance) ||
      !positive_finite(average_mass))
    throw NumericalError(fmt::format(
        "initial barrier stiffness: needs a positive bounding-box diagonal ({}), activation "
        "distance ({}) and average mass ({})",
        bbox_diagonal, band.activation_distance, average_mass));

  const double probe_gap =
      std::min(kStiffnessProbeGap * bbox_diagonal, band.activation_distance / 2);
  const double d0 = (band.thickness + probe_gap) * (band.thickness + probe_gap);
  const double curvature =
      4 * d0 * barrier_second_derivative(band.barrier_argument(d0), band.barrier_activation());
  BarrierStiffness stiffness;
  const double min = min_stiffness_scale * average_mass / curvature;
  stiffness.max = kStiffnessRange * min;

  const double barrier_sq = barrier_gradient.squaredNorm();
  const double balance = barrier_sq > 0 ? -barrier_gradient.dot(energy_gradient) / barrier_sq : min;
  stiffness.value = std::clamp(balance, min, stiffness.max);
  return stiffness;
}

BarrierStiffness update_barrier_stiffness(const BarrierStiffness& stiffness,
                                          double previous_min_distance, double min_distance,
                                          double bbox_diagonal, const BarrierBand& band,
                                          double gap_scale) {
  const double tolerance = gap_scale * bbox_diagonal;
  const double previous_gap = std::sqrt(previous_min_distance) - band.thickness;
  const double gap = std::sqrt(min_distance) - band.thickness;
  if (previous_gap < tolerance && gap < tolerance && gap < previous_gap)
    return {std::min(2 * stiffness.value, stiffness.max), stiffness.max};
  return stiffness;
}

}  // namespace psq
