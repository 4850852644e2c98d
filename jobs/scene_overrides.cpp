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
bool non_negative(double x) { return x >= 0; }
bool at_least_one(double x) { return x >= 1; }

/// The slots of the top-level parameters, by path, in the order parameter_paths lists them.
const std::vector<std::pair<std::string, Slot>>& scene_slots() {
  static const std::vector<std::pair<std::string, Slot>> slots = {
      {"time.step",
       {false, positive, "positive",
        [](Scene& s, const nlohmann::json& v) { s.time.step = v.get<double>(); }}},
      {"time.frames",
       {true, at_least_one, "at least 1",
        [](Scene& s, const nlohmann::json& v) { s.time.frames = v.get<int>(); }}},
      {"solver.tolerance",
       {false, positive, "positive",
        [](Scene& s, const nlohmann::json& v) { s.solver.tolerance = v.get<double>(); }}},
      {"solver.max_iterations",
       {true, at_least_one, "at least 1",
        [](Scene& s, const nlohmann::json& v) { s.solver.max_iterations = v.get<int>(); }}},
      {"contact.friction",
       {false, non_negative, "at least 0",
        [](Scene& s, const nlohmann::json& v) { s.contact.friction = v.get<double>(); }}},
  };
  return slots;
}

std::optional<Slot> scene_slot(const std::string& path) {
  for (const auto& [slot_path, slot] : scene_slots())
    if (slot_path == path) return slot;
  return std::nullopt;
}

/// A material parameter every shell has: "shell.<name>.material.<key>".
struct MaterialKey {
  std::string key;
  double Material::*field;
  std::function<bool(double)> valid;
  std::string rule;  ///< completes "must be ..."
};

const std::vector<MaterialKey>& material_keys() {
  static const std::vector<MaterialKey> keys = {
      {"youngs_modulus", &Material::youngs_modulus, positive, "positive"},
      {"poisson_ratio", &Material::poisson_ratio, [](double nu) { return nu > -1 && nu < 0.5; },
       "in (-1, 0.5)"},
      {"density", &Material::density, positive, "positive"},
      {"thickness", &Material::thickness, positive, "positive"},
  };
  return keys;
}

/// The slot of "shell.<name>.material.<key>" (the shell name may contain dots).
std::optional<Slot> material_slot(const Scene& scene, const std::string& path) {
  for (std::size_t index = 0; index < scene.shells.size(); ++index) {
    const std::string shell_prefix = "shell." + scene.shells[index].name + ".material.";
    if (!path.starts_with(shell_prefix)) continue;
    const std::string key = path.substr(shell_prefix.size());
    for (const MaterialKey& material : material_keys()) {
      if (material.key != key) continue;
      const auto set = [index, field = material.field](Scene& s, const nlohmann::json& v) {
        s.shells[index].material.*field = v.get<double>();
      };
      return Slot{false, material.valid, material.rule, set};
    }
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
  std::vector<std::string> paths;
  for (const auto& [path, slot] : scene_slots()) paths.push_back(path);
  for (const Shell& shell : scene.shells)
    for (const MaterialKey& material : material_keys())
      paths.push_back(fmt::format("shell.{}.material.{}", shell.name, material.key));
  return paths;
}

void check_parameter_path(const Scene& scene, const std::string& path) { find_slot(scene, path); }

nlohmann::json canonical_override(const Scene& scene, const std::string& path,
                                  const nlohmann::json& value) {
  const Slot slot = find_slot(scene, path);
  auto fail = [&](const std::string& requirement) -> OverrideError {
    return OverrideError(
        path, fmt::format("parameter '{}' must be {} (got {})", path, requirement, value.dump()));
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
