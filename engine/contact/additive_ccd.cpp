#include "engine/contact/additive_ccd.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/core/error.hpp"

namespace psq {
double distance_rounding_margin(double largest_coordinate) {
  // Multiple of ε_mach · max |coordinate| that covers the rounding of the positions and of the
  // distance computation.
  constexpr double kRoundingMarginFactor = 16.0;
  return kRoundingMarginFactor * std::numeric_limits<double>::epsilon() * largest_coordinate;
}

namespace {

using Eigen::Vector3d;

/// Displacements end − start without their mean (a common translation leaves distances alone).
PairPositions relative_displacements(const PairPositions& start, const PairPositions& end) {
  PairPositions displacement;
  Vector3d mean = Vector3d::Zero();
  for (int i = 0; i < 4; ++i) {
    displacement[i] = end[i] - start[i];
    mean += displacement[i];
  }
  mean /= 4.0;
  for (Vector3d& d : displacement) d -= mean;
  return displacement;
}

/// distance_rounding_margin of the pair's positions at both ends. A non-finite position is a
/// NumericalError: it must not pass as either safe or colliding.
double rounding_margin(const PairPositions& start, const PairPositions& end) {
  double largest = 0;
  for (int i = 0; i < 4; ++i) {
    if (!start[i].allFinite() || !end[i].allFinite())
      throw NumericalError("additive CCD: a vertex position is not finite (NaN or infinity)");
    largest = std::max({largest, start[i].cwiseAbs().maxCoeff(), end[i].cwiseAbs().maxCoeff()});
  }
  return distance_rounding_margin(largest);
}

/// The conservative-advancement loop shared by both pair types. `distance` maps the four
/// positions to the primitives' distance; `speed_bound` is l_p for `displacement`.
template <class Distance>
CcdResult advance(const PairPositions& start, const PairPositions& displacement, double speed_bound,
                  const AdditiveCcdSettings& settings, double margin, Distance distance) {
  assert(settings.rescaling > 0 && settings.rescaling < 1);
  assert(settings.ratio_bound > 0 && settings.ratio_bound < 1);
  const double contact = settings.min_distance + margin;
  auto distance_at = [&](double t) {
    PairPositions x;
    for (int i = 0; i < 4; ++i) x[i] = start[i] + t * displacement[i];
    return distance(x);
  };

  const double initial_gap = distance(start) - contact;
  if (!(initial_gap > 0)) return {true, 0.0, 0};
  if (speed_bound == 0) return {false, settings.t_max, 0};

  const double step_fraction = std::min(settings.rescaling, 1 - settings.ratio_bound);
  const double gap_bound = settings.ratio_bound * initial_gap;
  double t = 0, gap = initial_gap;
  for (int iteration = 1; iteration <= settings.max_iterations; ++iteration) {
    // Either advance keeps the gap above the bound while it closes at most at l_p; the second
    // is the longer once the pair has separated beyond its bound, which with r near 1 makes
    // the difference between a few advances and thousands for a pair moving apart.
    const double advance_length =
        std::max(step_fraction * gap, settings.rescaling * (gap - gap_bound));
    const double next_t = std::min(t + advance_length / speed_bound, settings.t_max);
    const double next_gap = distance_at(next_t) - contact;
    // The first advance keeps the gap above (1 − s′)(d₀ − ξ) ≥ r (d₀ − ξ) by construction;
    // testing it against the ratio bound would only let rounding reject a head-on approach.
    const bool within_bound = iteration == 1 ? next_gap > 0 : next_gap >= gap_bound;
    if (!within_bound) return {true, t, iteration};
    t = next_t;
    gap = next_gap;
    if (t >= settings.t_max) return {false, settings.t_max, iteration};
    if (t >= settings.stop_after) return {false, t, iteration};
  }
  return {true, t, settings.max_iterations};
}

/// l_p of a point–triangle pair: |Δp| + maxᵢ |Δtᵢ|.
double point_triangle_speed_bound(const PairPositions& displacement) {
  return displacement[0].norm() +
         std::max({displacement[1].norm(), displacement[2].norm(), displacement[3].norm()});
}

/// l_p of an edge–edge pair: max(|Δa0|, |Δa1|) + max(|Δb0|, |Δb1|).
double edge_edge_speed_bound(const PairPositions& displacement) {
  return std::max(displacement[0].norm(), displacement[1].norm()) +
         std::max(displacement[2].norm(), displacement[3].norm());
}

double point_triangle_gap_distance(const PairPositions& x) {
  return std::sqrt(point_triangle_distance(x[0], x[1], x[2], x[3]));
}

double edge_edge_gap_distance(const PairPositions& x) {
  return std::sqrt(edge_edge_distance(x[0], x[1], x[2], x[3]));
}

}  // namespace

double ccd_first_advance(const PairPositions& start, const PairPositions& end, bool edge_edge,
                         const AdditiveCcdSettings& settings) {
  const PairPositions displacement = relative_displacements(start, end);
  const double speed_bound = edge_edge ? edge_edge_speed_bound(displacement)
                                       : point_triangle_speed_bound(displacement);
  const double gap = (edge_edge ? edge_edge_gap_distance(start) : point_triangle_gap_distance(start)) -
                     settings.min_distance - rounding_margin(start, end);
  if (!(gap > 0)) return 0.0;
  if (speed_bound == 0) return std::numeric_limits<double>::infinity();
  return std::min(settings.rescaling, 1 - settings.ratio_bound) * gap / speed_bound;
}

void validate_ccd_settings(const AdditiveCcdSettings& settings) {
  auto require = [](bool ok, const char* name, double value, const char* range) {
    if (!ok) throw InputError(fmt::format("CCD setting {} = {} must be {}", name, value, range));
  };
  require(settings.rescaling > 0 && settings.rescaling < 1, "rescaling", settings.rescaling,
          "in (0, 1)");
  require(settings.ratio_bound > 0 && settings.ratio_bound < 1, "ratio_bound", settings.ratio_bound,
          "in (0, 1)");
  require(settings.min_distance >= 0 && std::isfinite(settings.min_distance), "min_distance",
          settings.min_distance, "finite and ≥ 0");
  require(settings.max_iterations >= 1, "max_iterations", settings.max_iterations, "≥ 1");
  require(settings.t_max > 0 && std::isfinite(settings.t_max), "t_max", settings.t_max,
          "finite and > 0");
}

CcdResult point_triangle_ccd(const PairPositions& start, const PairPositions& end,
                             const AdditiveCcdSettings& settings) {
  const PairPositions displacement = relative_displacements(start, end);
  return advance(start, displacement, point_triangle_speed_bound(displacement), settings,
                 rounding_margin(start, end), point_triangle_gap_distance);
}

CcdResult edge_edge_ccd(const PairPositions& start, const PairPositions& end,
                        const AdditiveCcdSettings& settings) {
  const PairPositions displacement = relative_displacements(start, end);
  return advance(start, displacement, edge_edge_speed_bound(displacement), settings,
                 rounding_margin(start, end), edge_edge_gap_distance);
}

}  // namespace psq
