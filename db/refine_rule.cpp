#include "db/refine_rule.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/core/error.hpp"

namespace psq::db {
namespace {

constexpr std::array<std::string_view, 7> kKindNames{"all",    "none",    "top",  "threshold",
                                                     "pareto", "changed", "where"};
constexpr std::array<std::string_view, 2> kPreferenceNames{"largest", "smallest"};
constexpr std::array<std::string_view, 6> kComparisonNames{"<", "<=", ">", ">=", "==", "!="};

template <class Enum, std::size_t N>
Enum from_name(const std::array<std::string_view, N>& names, const std::string& name) {
  for (std::size_t i = 0; i < N; ++i)
    if (names[i] == name) return static_cast<Enum>(i);
  throw std::invalid_argument(fmt::format("stored refine rule: unknown name '{}'", name));
}

std::string_view to_string(Preference preference) {
  return kPreferenceNames[static_cast<std::size_t>(preference)];
}

std::optional<double> value_of(const std::map<std::string, double>& values,
                               const std::string& name) {
  const auto found = values.find(name);
  if (found == values.end() || !std::isfinite(found->second)) return std::nullopt;
  return found->second;
}

/// An output of the last preview level, else a parameter.
std::optional<double> named_value(const PreviewPoint& point, const std::string& name) {
  if (auto output = value_of(point.outputs, name)) return output;
  return value_of(point.parameters, name);
}

bool compare(double left, Comparison op, double right) {
  switch (op) {
    case Comparison::less: return left < right;
    case Comparison::less_equal: return left <= right;
    case Comparison::greater: return left > right;
    case Comparison::greater_equal: return left >= right;
    case Comparison::equal: return left == right;
    case Comparison::not_equal: return left != right;
  }
  return false;
}

bool is_output(const std::string& name) {
  return std::find(kLevelOutputs.begin(), kLevelOutputs.end(), name) != kLevelOutputs.end();
}

/// A where condition must name something the points have, or it would silently select nothing.
void check_condition_names(const std::vector<Condition>& conditions,
                           const std::vector<PreviewPoint>& points) {
  for (const Condition& condition : conditions) {
    if (is_output(condition.name)) continue;
    const bool is_parameter = std::any_of(points.begin(), points.end(), [&](const PreviewPoint& p) {
      return p.parameters.count(condition.name) > 0;
    });
    if (is_parameter) continue;
    std::vector<std::string> names(kLevelOutputs.begin(), kLevelOutputs.end());
    if (!points.empty())
      for (const auto& [path, value] : points.front().parameters) names.push_back(path);
    throw InputError(fmt::format("'{}' is neither an output nor a parameter of the previewed "
                                 "jobs; use one of: {}",
                                 condition.name, fmt::join(names, ", ")));
  }
}

std::vector<std::string> select_meeting(const std::vector<Condition>& conditions,
                                        const std::vector<PreviewPoint>& points) {
  std::vector<std::string> selected;
  for (const PreviewPoint& point : points) {
    const bool meets = std::all_of(conditions.begin(), conditions.end(), [&](const Condition& c) {
      const auto value = named_value(point, c.name);
      return value && compare(*value, c.op, c.value);
    });
    if (meets) selected.push_back(point.job_id);
  }
  return selected;
}

/// The first `count` of the points that have a score, best first (ties: the earlier point),
/// returned in the order of `points`.
std::vector<std::string> select_best(const std::vector<PreviewPoint>& points,
                                     const std::vector<std::optional<double>>& scores,
                                     Preference preference, int count) {
  std::vector<std::size_t> ranked;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (scores[i]) ranked.push_back(i);
  std::stable_sort(ranked.begin(), ranked.end(), [&](std::size_t a, std::size_t b) {
    return preference == Preference::largest ? *scores[a] > *scores[b] : *scores[a] < *scores[b];
  });
  ranked.resize(std::min(ranked.size(), static_cast<std::size_t>(std::max(count, 0))));
  std::sort(ranked.begin(), ranked.end());
  std::vector<std::string> selected;
  for (const std::size_t i : ranked) selected.push_back(points[i].job_id);
  return selected;
}

/// The value of `objective` oriented so that smaller is better.
std::optional<double> cost(const PreviewPoint& point, const Objective& objective) {
  const auto value = value_of(point.outputs, objective.output);
  if (!value) return std::nullopt;
  return objective.preference == Preference::smallest ? *value : -*value;
}

std::vector<std::string> select_pareto(const std::vector<Objective>& objectives,
                                       const std::vector<PreviewPoint>& points) {
  std::vector<std::array<double, 2>> costs;
  std::vector<std::size_t> candidates;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto first = cost(points[i], objectives.at(0));
    const auto second = cost(points[i], objectives.at(1));
    if (!first || !second) continue;
    candidates.push_back(i);
    costs.push_back({*first, *second});
  }
  const auto dominates = [](const std::array<double, 2>& a, const std::array<double, 2>& b) {
    return a[0] <= b[0] && a[1] <= b[1] && (a[0] < b[0] || a[1] < b[1]);
  };
  std::vector<std::string> selected;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const bool dominated = std::any_of(costs.begin(), costs.end(), [&](const auto& other) {
      return dominates(other, costs[c]);
    });
    if (!dominated) selected.push_back(points[candidates[c]].job_id);
  }
  return selected;
}

std::vector<std::string> select_changed(const RefineRule& rule,
                                        const std::vector<PreviewPoint>& points) {
  std::vector<std::optional<double>> changes;
  for (const PreviewPoint& point : points) changes.push_back(relative_change(point, rule.by));
  if (rule.count) return select_best(points, changes, Preference::largest, *rule.count);
  std::vector<std::string> selected;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (changes[i] && rule.change_above && *changes[i] > *rule.change_above)
      selected.push_back(points[i].job_id);
  return selected;
}

}  // namespace

std::string_view to_string(RefineKind kind) { return kKindNames[static_cast<std::size_t>(kind)]; }

std::string_view to_string(Comparison op) {
  return kComparisonNames[static_cast<std::size_t>(op)];
}

nlohmann::json to_json(const RefineRule& rule) {
  nlohmann::json stored = {{"kind", to_string(rule.kind)}};
  if (rule.preview) stored["preview"] = *rule.preview;
  if (!rule.by.empty()) stored["by"] = rule.by;
  if (rule.kind == RefineKind::top) stored["preference"] = to_string(rule.preference);
  if (rule.count) stored["count"] = *rule.count;
  if (rule.change_above) stored["change_above"] = *rule.change_above;
  for (const Condition& c : rule.conditions)
    stored["conditions"].push_back({{"name", c.name}, {"op", to_string(c.op)}, {"value", c.value}});
  for (const Objective& o : rule.objectives)
    stored["objectives"].push_back({{"output", o.output}, {"preference", to_string(o.preference)}});
  return stored;
}

RefineRule refine_rule_from_json(const nlohmann::json& stored) {
  RefineRule rule;
  rule.kind = from_name<RefineKind>(kKindNames, stored.at("kind").get<std::string>());
  if (stored.contains("preview")) rule.preview = stored["preview"].get<int>();
  rule.by = stored.value("by", "");
  if (stored.contains("preference"))
    rule.preference = from_name<Preference>(kPreferenceNames, stored["preference"].get<std::string>());
  if (stored.contains("count")) rule.count = stored["count"].get<int>();
  if (stored.contains("change_above")) rule.change_above = stored["change_above"].get<double>();
  for (const auto& c : stored.value("conditions", nlohmann::json::array()))
    rule.conditions.push_back({c.at("name").get<std::string>(),
                               from_name<Comparison>(kComparisonNames, c.at("op").get<std::string>()),
                               c.at("value").get<double>()});
  for (const auto& o : stored.value("objectives", nlohmann::json::array()))
    rule.objectives.push_back(
        {o.at("output").get<std::string>(),
         from_name<Preference>(kPreferenceNames, o.at("preference").get<std::string>())});
  return rule;
}

std::string describe(const RefineRule& rule) {
  std::string what;
  switch (rule.kind) {
    case RefineKind::all: return "every level of every job";
    case RefineKind::none: what = "no automatic selection (psq promote selects)"; break;
    case RefineKind::top:
      what = fmt::format("the {} {} by {}", *rule.count, to_string(rule.preference), rule.by);
      break;
    case RefineKind::changed:
      what = rule.count ? fmt::format("the {} whose {} changed most", *rule.count, rule.by)
                        : fmt::format("those whose {} changed by more than {:g}", rule.by,
                                      *rule.change_above);
      break;
    case RefineKind::pareto:
      what = fmt::format("the Pareto-optimal points of {} ({}) and {} ({})",
                         rule.objectives.at(0).output,
                         to_string(rule.objectives.at(0).preference), rule.objectives.at(1).output,
                         to_string(rule.objectives.at(1).preference));
      break;
    case RefineKind::threshold:
    case RefineKind::where: {
      std::vector<std::string> terms;
      for (const Condition& c : rule.conditions)
        terms.push_back(fmt::format("{} {} {:g}", c.name, to_string(c.op), c.value));
      what = fmt::format("those with {}", fmt::join(terms, " and "));
      break;
    }
  }
  const std::string preview =
      rule.preview ? fmt::format("{} preview level{}", *rule.preview, *rule.preview == 1 ? "" : "s")
                   : std::string("every level but the finest");
  return fmt::format("coarse-first: {} as preview, then {}", preview, what);
}

std::optional<double> relative_change(const PreviewPoint& point, const std::string& output) {
  const auto last = value_of(point.outputs, output);
  const auto earlier = value_of(point.earlier_outputs, output);
  if (!last || !earlier) return std::nullopt;
  const double scale = std::max(std::abs(*last), std::abs(*earlier));
  return scale == 0 ? 0.0 : std::abs(*last - *earlier) / scale;
}

std::vector<std::string> select_points(const RefineRule& rule,
                                       const std::vector<PreviewPoint>& points) {
  switch (rule.kind) {
    case RefineKind::all:
    case RefineKind::none:
      return {};
    case RefineKind::top: {
      std::vector<std::optional<double>> scores;
      for (const PreviewPoint& point : points) scores.push_back(value_of(point.outputs, rule.by));
      return select_best(points, scores, rule.preference, rule.count.value_or(0));
    }
    case RefineKind::threshold:
    case RefineKind::where:
      check_condition_names(rule.conditions, points);
      return select_meeting(rule.conditions, points);
    case RefineKind::pareto:
      return select_pareto(rule.objectives, points);
    case RefineKind::changed:
      return select_changed(rule, points);
  }
  return {};
}

}  // namespace psq::db
