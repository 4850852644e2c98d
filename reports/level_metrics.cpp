#include "reports/level_metrics.hpp"

#include <cmath>
#include <numeric>
#include <stdexcept>

namespace psq::reports {

double bounding_box_diagonal(const Positions& points) {
  if (points.rows() == 0) return 0.0;
  return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
}

double max_point_distance(const Positions& a, const Positions& b) {
  if (a.rows() != b.rows())
    throw std::invalid_argument("point sets of different sizes (" + std::to_string(a.rows()) +
                                " and " + std::to_string(b.rows()) + " vertices)");
  if (a.rows() == 0) return 0.0;
  return (a - b).rowwise().norm().maxCoeff();
}

double relative_error_to_finest(const Positions& prolonged, const Positions& finest) {
  const double diagonal = bounding_box_diagonal(finest);
  if (!(diagonal > 0.0))
    throw std::invalid_argument("the finest level's bounding box is a single point");
  return max_point_distance(prolonged, finest) / diagonal;
}

std::optional<double> level_seconds(const std::map<std::string, double>& timings) {
  for (const char* whole : {"wall", "total"})
    if (const auto found = timings.find(whole); found != timings.end()) return found->second;
  if (timings.empty()) return std::nullopt;
  return std::accumulate(timings.begin(), timings.end(), 0.0,
                         [](double sum, const auto& phase) { return sum + phase.second; });
}

std::optional<double> final_residual(const std::vector<double>& residuals) {
  for (auto value = residuals.rbegin(); value != residuals.rend(); ++value)
    if (std::isfinite(*value)) return *value;
  return std::nullopt;
}

}  // namespace psq::reports
