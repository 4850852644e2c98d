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

/// A smallest gap that changed by less than this factor since the last update has stalled.
constexpr double kStalledGapChange = 2.0;

/// The barrier's push per unit κ across a gap g, |∂b/∂g| = 2 (ξ + g) |b′(s)| with
/// s = (ξ + g)² − ξ².
double barrier_push(double gap, const BarrierBand& band) {
  const double root = band.thickness + gap;
  return 2 * root *
         std::abs(barrier_first_derivative(band.barrier_argument(root * root),
                                           band.barrier_activation()));
}

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
                                          double gap_scale, bool steps_cut_by_ccd) {
  const double tolerance = gap_scale * bbox_diagonal;
  const double previous_gap = std::sqrt(previous_min_distance) - band.thickness;
  const double gap = std::sqrt(min_distance) - band.thickness;
  if (!(gap < tolerance)) return stiffness;
  double factor = previous_gap < tolerance && gap < previous_gap ? 2.0 : 1.0;
  const bool stalled = previous_gap < tolerance && gap > previous_gap / kStalledGapChange &&
                       gap < kStalledGapChange * previous_gap;
  if (steps_cut_by_ccd && stalled)
    factor = std::max(factor, barrier_push(gap, band) / barrier_push(tolerance, band));
  return {std::min(factor * stiffness.value, stiffness.max), stiffness.max};
}

}  // namespace psq
