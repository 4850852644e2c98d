#pragma once
// The numbers a report derives from checkpoints and level records: displacement, the error of
// a level against the finest one, a level's run time and its final residual.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq::reports {

/// Length of the diagonal of the axis-aligned bounding box of the points; 0 for no points.
double bounding_box_diagonal(const Positions& points);

/// max_i ‖a_i − b_i‖. Both must have the same shape (throws std::invalid_argument otherwise).
double max_point_distance(const Positions& a, const Positions& b);

/// Error of a level's result against the finest level's converged result of the same job:
///   max_i ‖p_i − f_i‖ / diag(f),
/// with p the level's state prolonged to the finest mesh and f the finest level's positions.
/// Throws std::invalid_argument for different shapes or a degenerate (zero) bounding box.
double relative_error_to_finest(const Positions& prolonged, const Positions& finest);

/// Seconds a level took, from its named phase timings: the phase "wall" if recorded, else
/// "total", else the sum of all phases (then taken to be disjoint). Empty without timings.
std::optional<double> level_seconds(const std::map<std::string, double>& timings);

/// The last finite value of a residual history; empty if there is none.
std::optional<double> final_residual(const std::vector<double>& residuals);

}  // namespace psq::reports
