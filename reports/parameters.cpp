#include "reports/parameters.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <set>

namespace psq::reports {
namespace {

void flatten_into(const nlohmann::json& value, const std::string& path,
                  std::map<std::string, nlohmann::json>& flat) {
  if (!value.is_object()) {
    flat[path.empty() ? "value" : path] = value;
    return;
  }
  for (const auto& [key, child] : value.items())
    flatten_into(child, path.empty() ? key : path + "." + key, flat);
}

}  // namespace

std::map<std::string, nlohmann::json> flatten_parameters(const nlohmann::json& parameters) {
  std::map<std::string, nlohmann::json> flat;
  flatten_into(parameters, "", flat);
  return flat;
}

std::vector<std::string> varying_parameters(
    const std::vector<std::map<std::string, nlohmann::json>>& parameter_sets) {
  std::set<std::string> names;
  for (const auto& set : parameter_sets)
    for (const auto& [name, value] : set) names.insert(name);
  std::vector<std::string> varying;
  for (const std::string& name : names) {
    // A name absent from the first set differs from it in every set that has it.
    const auto& first_set = parameter_sets.front();
    const auto first = first_set.find(name);
    const auto differs_from_first = [&](const std::map<std::string, nlohmann::json>& set) {
      const auto found = set.find(name);
      return found == set.end() || first == first_set.end() || found->second != first->second;
    };
    const bool differs =
        std::any_of(parameter_sets.begin(), parameter_sets.end(), differs_from_first);
    if (differs) varying.push_back(name);
  }
  return varying;
}

std::string exact_text(double value) {
  // fmt's "{}" is the shortest exact text in plain or exponent form ("40", "2000000000"); the
  // shortest exact "%g" text is often shorter for round powers of ten ("2e+09").
  std::string scientific;
  for (int digits = 1; digits <= 17; ++digits) {
    scientific = fmt::format("{:.{}g}", value, digits);
    double parsed = 0;
    std::from_chars(scientific.data(), scientific.data() + scientific.size(), parsed);
    if (parsed == value) break;
  }
  std::string plain = fmt::format("{}", value);
  return scientific.size() < plain.size() ? scientific : plain;
}

std::string cell_text(const nlohmann::json& value) {
  if (value.is_null()) return "";
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) return exact_text(value.get<double>());
  return value.dump();
}

std::string short_name(const std::string& name) {
  const auto dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(dot + 1);
}

std::string parameter_values(const std::map<std::string, nlohmann::json>& parameters,
                             const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    const auto found = parameters.find(name);
    const std::string value = found == parameters.end() ? "-" : cell_text(found->second);
    text += fmt::format("{}{}={}", text.empty() ? "" : ", ", short_name(name), value);
  }
  return text;
}

}  // namespace psq::reports
