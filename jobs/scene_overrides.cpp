#include "jobs/scene_overrides.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <climits>
#include <cmath>
#include <functional>
#include <optional>

#include "engine/scene/key_suggestion.hpp"

namespace psq::jobs {
namespace {

/// One overridable value of a scene: its type, the rule its values obey and how to set it.
struct Slot {
  bool integer = false;
  std::function<bool(double)> valid;
  std::string rule;  ///< completes "must be ..."
  std::function<void(Scene&, const nlohmann::json&)> set;
};

bool positive(double x) { return x > 0; }
bool at_least_one(double x) { return x >= 1; }

/// The slots of the top-level parameters, by path.
std::optional<Slot> scene_slot(const std::string& path) {
  if (path == "time.step")
    return Slot{false, positive, "positive",
                [](Scene& s, const nlohmann::json& v) { s.time.step = v.get<double>(); }};
  if (path == "time.frames")
    return Slot{true, at_least_one, "at least 1",
                [](Scene& s, const nlohmann::json& v) { s.time.frames = v.get<int>(); }};
  if (path == "solver.tolerance")
    return Slot{false, positive, "positive",
                [](Scene& s, const nlohmann::json& v) { s.solver.tolerance = v.get<double>(); }};
  if (path == "solver.max_iterations")
    return Slot{true, at_least_one, "at least 1",
                [](Scene& s, const nlohmann::json& v) { s.solver.max_iterations = v.get<int>(); }};
  return std::nullopt;
}

const std::vector<std::string> kScenePaths = {"time.step", "time.frames", "solver.tolerance",
                                              "solver.max_iterations"};
const std::vector<std::string> kMaterialKeys = {"youngs_modulus", "poisson_ratio", "density",
                                                "thickness"};

/// The slot of "shell.<name>.material.<key>" (the shell name may contain dots).
std::optional<Slot> material_slot(const Scene& scene, const std::string& path) {
  const std::string prefix = "shell.";
  if (path.rfind(prefix, 0) != 0) return std::nullopt;
  for (std::size_t index = 0; index < scene.shells.size(); ++index) {
    const std::string shell_prefix = prefix + scene.shells[index].name + ".material.";
    if (path.rfind(shell_prefix, 0) != 0) continue;
    const std::string key = path.substr(shell_prefix.size());
    auto field = [index, key](Scene& s) -> double& {
      Material& m = s.shells[index].material;
      if (key == "youngs_modulus") return m.youngs_modulus;
      if (key == "poisson_ratio") return m.poisson_ratio;
      if (key == "density") return m.density;
      return m.thickness;
    };
    auto set = [field](Scene& s, const nlohmann::json& v) { field(s) = v.get<double>(); };
    if (key == "poisson_ratio")
      return Slot{false, [](double nu) { return nu > -1 && nu < 0.5; }, "in (-1, 0.5)", set};
    if (key == "youngs_modulus" || key == "density" || key == "thickness")
      return Slot{false, positive, "positive", set};
  }
  return std::nullopt;
}

[[noreturn]] void fail_unknown(const Scene& scene, const std::string& path) {
  const std::vector<std::string> known = parameter_paths(scene);
  const auto suggestion = suggest_key(path, known);
  throw OverrideError(path, suggestion ? fmt::format("unknown parameter '{}'; did you mean '{}'?",
                                                     path, *suggestion)
                                       : fmt::format("unknown parameter '{}'; valid parameters: {}",
                                                     path, fmt::join(known, ", ")));
}

Slot find_slot(const Scene& scene, const std::string& path) {
  if (auto slot = scene_slot(path)) return *slot;
  if (auto slot = material_slot(scene, path)) return *slot;
  fail_unknown(scene, path);
}

}  // namespace

std::vector<std::string> parameter_paths(const Scene& scene) {
  std::vector<std::string> paths = kScenePaths;
  for (const Shell& shell : scene.shells)
    for (const std::string& key : kMaterialKeys)
      paths.push_back(fmt::format("shell.{}.material.{}", shell.name, key));
  return paths;
}

void check_parameter_path(const Scene& scene, const std::string& path) {
  find_slot(scene, path);
}

nlohmann::json canonical_override(const Scene& scene, const std::string& path,
                                  const nlohmann::json& value) {
  const Slot slot = find_slot(scene, path);
  auto fail = [&](const std::string& requirement) -> OverrideError {
    return OverrideError(path, fmt::format("parameter '{}' must be {} (got {})", path, requirement,
                                           value.dump()));
  };
  if (slot.integer) {
    if (!value.is_number_integer()) throw fail("an integer");
    const auto number = value.get<std::int64_t>();
    if (number > INT_MAX || !slot.valid(static_cast<double>(number))) throw fail(slot.rule);
    return number;
  }
  if (!value.is_number()) throw fail("a number");
  const auto number = value.get<double>();
  if (!std::isfinite(number)) throw fail("finite");
  if (!slot.valid(number)) throw fail(slot.rule);
  return number;
}

Scene apply_overrides(Scene scene, const Overrides& overrides) {
  for (const auto& [path, value] : overrides)
    find_slot(scene, path).set(scene, canonical_override(scene, path, value));
  return scene;
}

}  // namespace psq::jobs
