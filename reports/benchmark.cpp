#include "reports/benchmark.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "reports/parameters.hpp"

namespace psq::reports {
namespace {

bool finite(const std::pair<double, double>& point) {
  return std::isfinite(point.first) && std::isfinite(point.second);
}

bool dominates(const std::pair<double, double>& a, const std::pair<double, double>& b) {
  return a.first <= b.first && a.second <= b.second && (a.first < b.first || a.second < b.second);
}

/// The points of `job`'s levels that have a time and an error to the reference.
void add_points(const JobReport& job, std::vector<BenchmarkPoint>& points) {
  for (std::size_t l = 0; l < job.levels.size(); ++l) {
    const std::optional<double> seconds = job.seconds_through(l);
    const std::optional<double> error = job.levels[l].error_to_reference;
    if (seconds && error) points.push_back({&job, l, *seconds, *error, false});
  }
}

void mark_front(std::vector<BenchmarkPoint>& points) {
  std::vector<std::pair<double, double>> costs;
  for (const BenchmarkPoint& point : points) costs.emplace_back(point.seconds, point.error);
  for (const std::size_t i : pareto_front(costs)) points[i].on_front = true;
}

}  // namespace

std::vector<std::size_t> pareto_front(const std::vector<std::pair<double, double>>& points) {
  std::vector<std::size_t> front;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!finite(points[i])) continue;
    const bool dominated = std::any_of(points.begin(), points.end(), [&](const auto& other) {
      return finite(other) && dominates(other, points[i]);
    });
    if (!dominated) front.push_back(i);
  }
  std::stable_sort(front.begin(), front.end(),
                   [&](std::size_t a, std::size_t b) { return points[a] < points[b]; });
  return front;
}

const JobReport* baseline_of(const SweepReport& report, const JobReport& job, db::Method method) {
  for (const JobReport& other : report.jobs)
    if (other.finished() && other.job.method == method &&
        design_point(other.job) == design_point(job.job))
      return &other;
  return nullptr;
}

std::vector<std::string> design_parameters(const SweepReport& report) {
  std::vector<std::string> names;
  std::copy_if(report.swept_parameters.begin(), report.swept_parameters.end(),
               std::back_inserter(names),
               [](const std::string& name) { return name != "depth" && name != "method"; });
  return names;
}

std::vector<BenchmarkScene> benchmark_scenes(const SweepReport& report) {
  const std::vector<std::string> parameters = design_parameters(report);
  std::vector<BenchmarkScene> scenes;
  std::vector<std::string> seen;  // design points already gathered
  for (const JobReport& first : report.jobs) {
    const std::string point = design_point(first.job);
    if (std::find(seen.begin(), seen.end(), point) != seen.end()) continue;
    seen.push_back(point);
    const JobReport* reference = baseline_of(report, first, db::Method::direct_final);
    if (!reference) continue;
    BenchmarkDesignPoint design{parameter_values(first.parameters, parameters), reference, {}};
    for (const JobReport& job : report.jobs)
      if (job.finished() && design_point(job.job) == point) add_points(job, design.points);
    const bool compared = std::any_of(design.points.begin(), design.points.end(),
                                      [&](const BenchmarkPoint& p) { return p.job != reference; });
    if (!compared) continue;
    mark_front(design.points);
    const auto scene = std::find_if(scenes.begin(), scenes.end(), [&](const BenchmarkScene& s) {
      return s.scene == first.job.scene;
    });
    if (scene == scenes.end())
      scenes.push_back({first.job.scene, {std::move(design)}});
    else
      scene->design_points.push_back(std::move(design));
  }
  return scenes;
}

}  // namespace psq::reports
