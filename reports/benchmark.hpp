#pragma once
// Run time against error, the comparison of the benchmark sweeps (methods × depth ×
// resolution): every level of every finished job is a point (the wall time up to that level,
// its error to its design point's reference), and each design point has its Pareto front. The
// benchmark plot and table both read these points, so they cannot disagree.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "reports/report_model.hpp"

namespace psq::reports {

/// Indices of the points that no other point dominates, sorted by x, then y. A point dominates
/// another when it is no larger in both coordinates and smaller in at least one, so equal points
/// are all on the front. Points with a non-finite coordinate are neither on the front nor
/// dominate.
std::vector<std::size_t> pareto_front(const std::vector<std::pair<double, double>>& points);

/// The finished job of `method` at `job`'s design point (design_point), if the sweep has one.
const JobReport* baseline_of(const SweepReport& report, const JobReport& job, db::Method method);

/// The swept parameters that tell design points apart: all but the method and the depth.
std::vector<std::string> design_parameters(const SweepReport& report);

/// One level of a finished job against its design point's reference.
struct BenchmarkPoint {
  const JobReport* job = nullptr;
  std::size_t level = 0;
  double seconds = 0;     ///< the wall time of the job's levels up to and including this one
  double error = 0;       ///< LevelReport::error_to_reference: 0 for the reference itself
  bool on_front = false;  ///< on its design point's Pareto front of (seconds, error)
};

/// The jobs of one design point (the same scene and overrides: the same problem on the same
/// finest mesh) against its reference, the finished direct_final job there. Errors of different
/// design points are to different references, so each has a front of its own.
struct BenchmarkDesignPoint {
  std::string label;  ///< its design parameters and their values; empty when there are none
  const JobReport* reference = nullptr;
  /// Every level with a time and an error, in job and level order, the reference's included.
  std::vector<BenchmarkPoint> points;
};

/// The design points of one scene file.
struct BenchmarkScene {
  std::string scene;  ///< the scene file as the store records it
  std::vector<BenchmarkDesignPoint> design_points;
};

/// The sweep's comparison, by scene and design point in the order their jobs were added: only
/// design points with a reference and at least one other finished job measured against it.
/// Empty when the sweep has none (it does not vary `method`, or no direct_final job finished).
std::vector<BenchmarkScene> benchmark_scenes(const SweepReport& report);

}  // namespace psq::reports
