#include "jobs/sweep_file.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <system_error>
#include <utility>

#include "engine/core/error.hpp"
#include "engine/core/input_file.hpp"
#include "engine/scene/key_suggestion.hpp"
#include "jobs/scene_overrides.hpp"

namespace psq::jobs {
namespace {

namespace fs = std::filesystem;

const std::string kDepth = "depth";
const std::string kMethod = "method";
const std::string kRefine = "refine";
/// A job's levels are its depth, which replaces the scene's [hierarchy] levels.
const std::string kSceneLevels = "hierarchy.levels";

/// Far more jobs than a sweep is run with; a larger product of the axes is almost surely a
/// mistake (a long list in a [grid] meant for a [[zip]]), and expanding and validating it one
/// job at a time would hang the reader before it reports anything.
constexpr std::size_t kMaxJobs = 10'000;

long line_of(const toml::node& node) { return static_cast<long>(node.source().begin.line); }

/// A value as written in the sweep file, with its line.
struct Value {
  nlohmann::json raw;
  long line = 0;
};

/// Parameters varied together: one path for a [grid] list, several for a [[zip]] group.
/// columns[p][i] is the i-th value of paths[p]; every column has the same length.
struct Axis {
  std::vector<std::string> paths;
  std::vector<std::vector<Value>> columns;
  std::size_t size() const { return columns.front().size(); }
};

/// Reads a sweep file's TOML and raises located InputErrors about it.
class SweepReader {
 public:
  SweepReader(std::string_view text, fs::path file)
      : file_(std::move(file)), document_(parse(text)) {}

  Sweep read() {
    allow_only(document_, {"name", "scene", kDepth, kMethod, "grid", "zip", kRefine},
               "at the top level");
    Sweep sweep;
    sweep.file = file_;
    sweep.name = required_string("name");
    sweep.scene = scene_path();
    sweep.scene_hash = file_content_hash(sweep.scene);
    sweep.refine = read_refine();
    const SceneDocument base = SceneDocument::read(sweep.scene);
    const std::vector<Axis> axes = read_axes(base);
    check_job_count(axes);
    const std::map<std::string, Value> defaults = top_level_defaults(axes);
    std::map<std::string, std::size_t> index_of_id;
    for_each_combination(axes, [&](const std::vector<std::size_t>& pick) {
      auto [job, depth_ignored] = make_job(base, sweep.scene_hash, axes, pick, defaults);
      const auto [it, inserted] = index_of_id.emplace(job.id, sweep.jobs.size());
      // A job of a method without a hierarchy is the same at every depth: listed once.
      if (!inserted && depth_ignored) return;
      if (!inserted)
        fail(0, fmt::format("jobs {} and {} have the same parameters ({}); a value is listed twice",
                            it->second + 1, sweep.jobs.size() + 1, describe_parameters(job)));
      sweep.jobs.push_back(std::move(job));
    });
    check_refine_depths(sweep);
    return sweep;
  }

 private:
  [[noreturn]] void fail(long line, const std::string& message) const {
    throw InputError(located_message(file_.string(), line, message));
  }

  toml::table parse(std::string_view text) const {
    try {
      return toml::parse(text, file_.string());
    } catch (const toml::parse_error& error) {
      fail(line_of_error(error), fmt::format("TOML syntax error: {}", error.description()));
    }
  }

  static long line_of_error(const toml::parse_error& error) {
    return static_cast<long>(error.source().begin.line);
  }

  /// Rejects the first key of `table` (in file order) not in `allowed`, suggesting the nearest.
  void allow_only(const toml::table& table, const std::vector<std::string>& allowed,
                  const std::string& where) const {
    const toml::key* unknown = nullptr;
    for (auto&& [key, value] : table) {
      if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
      if (!unknown || key.source().begin.line < unknown->source().begin.line) unknown = &key;
    }
    if (!unknown) return;
    const auto suggestion = suggest_key(unknown->str(), allowed);
    fail(static_cast<long>(unknown->source().begin.line),
         fmt::format("unknown key '{}' {}; {}", unknown->str(), where,
                     suggestion ? fmt::format("did you mean '{}'?", *suggestion)
                                : fmt::format("valid keys: {}", fmt::join(allowed, ", "))));
  }

  std::string required_string(const std::string& key) const {
    const toml::node* node = document_.get(key);
    if (!node) fail(0, fmt::format("missing '{}' at the top level", key));
    const auto value = node->value<std::string>();
    if (!node->is_string() || value->empty())
      fail(line_of(*node), fmt::format("'{}' must be a non-empty string", key));
    return *value;
  }

  /// The base scene, relative to the sweep file's directory.
  fs::path scene_path() const {
    const fs::path scene = (file_.parent_path() / required_string("scene")).lexically_normal();
    // Without the error code, a name the OS refuses (e.g. too long) would throw filesystem_error.
    std::error_code error;
    if (!fs::is_regular_file(scene, error))
      fail(line_of(*document_.get("scene")),
           error ? fmt::format("scene file '{}': {}", scene.string(), error.message())
                 : fmt::format("scene file '{}' does not exist", scene.string()));
    return scene;
  }

  static nlohmann::json scalar_json(const toml::node& node) {
    if (const auto* integer = node.as_integer()) return integer->get();
    if (const auto* real = node.as_floating_point()) return real->get();
    if (const auto* boolean = node.as_boolean()) return boolean->get();
    if (const auto* text = node.as_string()) return text->get();
    return nullptr;
  }

  /// The values of the list at `path` ("'path' in [grid]" in messages).
  std::vector<Value> read_list(const std::string& path, const toml::node& node,
                               const std::string& where) const {
    const toml::array* list = node.as_array();
    if (!list || list->empty())
      fail(line_of(node),
           fmt::format("'{}' {} must be a non-empty list of values, e.g. [1, 2]", path, where));
    std::vector<Value> values;
    for (const toml::node& element : *list) {
      nlohmann::json value = scalar_json(element);
      if (value.is_null())
        fail(line_of(element), fmt::format("'{}' {} must list numbers, not arrays or tables",
                                           path, where));
      values.push_back({std::move(value), line_of(element)});
    }
    return values;
  }

  /// Every list in `table` by dotted path: `a.b = [..]` and `"a.b" = [..]` are the same path.
  void collect_lists(const toml::table& table, const std::string& prefix, const std::string& where,
                     std::vector<std::pair<std::string, std::vector<Value>>>& lists) const {
    for (auto&& [key, node] : table) {
      const std::string path = prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
      if (const toml::table* nested = node.as_table())
        collect_lists(*nested, path, where, lists);
      else
        lists.emplace_back(path, read_list(path, node, where));
    }
  }

  /// The [grid] lists (one axis each) and the [[zip]] groups, each path checked against the
  /// scene and varied once.
  std::vector<Axis> read_axes(const SceneDocument& base) const {
    std::vector<Axis> axes;
    std::set<std::string> varied;
    auto add_path = [&](Axis& axis, std::string path, std::vector<Value> values) {
      const long line = values.front().line;
      if (!varied.insert(path).second)
        fail(line, fmt::format("parameter '{}' is varied twice; list it once", path));
      if (path == kSceneLevels)
        fail(line, fmt::format("'{}' has no effect in a job, whose levels are its depth; vary "
                               "'{}' instead",
                               kSceneLevels, kDepth));
      if (path != kDepth && path != kMethod) {
        try {
          base.check_path(path);
        } catch (const OverrideError& error) {
          fail(line, error.what());
        }
      }
      axis.paths.push_back(std::move(path));
      axis.columns.push_back(std::move(values));
    };
    if (const toml::node* grid = document_.get("grid")) {
      if (!grid->is_table()) fail(line_of(*grid), "'grid' must be a table: [grid]");
      std::vector<std::pair<std::string, std::vector<Value>>> lists;
      collect_lists(*grid->as_table(), "", "in [grid]", lists);
      for (auto& [path, values] : lists) add_path(axes.emplace_back(), path, std::move(values));
    }
    if (const toml::node* zips = document_.get("zip")) {
      const toml::array* groups = zips->as_array();
      if (!groups || !groups->is_array_of_tables())
        fail(line_of(*zips), "'zip' must be an array of tables: [[zip]]");
      for (const toml::node& group : *groups) {
        std::vector<std::pair<std::string, std::vector<Value>>> lists;
        collect_lists(*group.as_table(), "", "in [[zip]]", lists);
        if (lists.empty()) fail(line_of(group), "a [[zip]] group must list at least one parameter");
        for (const auto& [path, values] : lists)
          if (values.size() != lists.front().second.size())
            fail(line_of(group),
                 fmt::format("the lists of a [[zip]] group must have equal lengths: '{}' has {} "
                             "values, '{}' has {}",
                             lists.front().first, lists.front().second.size(), path,
                             values.size()));
        Axis& axis = axes.emplace_back();
        for (auto& [path, values] : lists) add_path(axis, path, std::move(values));
      }
    }
    return axes;
  }

  void check_job_count(const std::vector<Axis>& axes) const {
    // In floating point, as the product of a few hundred-value axes overflows std::size_t.
    double count = 1;
    for (const Axis& axis : axes) count *= static_cast<double>(axis.size());
    if (count > kMaxJobs)
      fail(0, fmt::format("the sweep expands to {:.0f} jobs, more than the {} a sweep may hold; "
                          "split it into several sweeps or zip lists that vary together",
                          count, kMaxJobs));
  }

  /// The `depth` and `method` of jobs whose axes do not vary them, as the top level gives
  /// them; absent when it does not (depth 1, the method the depth implies).
  std::map<std::string, Value> top_level_defaults(const std::vector<Axis>& axes) const {
    std::map<std::string, Value> defaults;
    for (const std::string& key : {kDepth, kMethod}) {
      const toml::node* node = document_.get(key);
      if (!node) continue;
      for (const Axis& axis : axes)
        for (const std::string& path : axis.paths)
          if (path == key)
            fail(line_of(*node),
                 fmt::format("'{}' is given at the top level and varied; give it once", key));
      defaults[key] = {scalar_json(*node), line_of(*node)};
    }
    if (!defaults.count(kDepth)) defaults[kDepth] = {1, 0};
    return defaults;
  }

  /// Calls `visit` with every combination of one index per axis, the last axis fastest.
  static void for_each_combination(const std::vector<Axis>& axes,
                                   const std::function<void(const std::vector<std::size_t>&)>& visit) {
    std::vector<std::size_t> pick(axes.size(), 0);
    while (true) {
      visit(pick);
      std::size_t axis = axes.size();
      while (axis > 0 && ++pick[axis - 1] == axes[axis - 1].size()) pick[--axis] = 0;
      if (axis == 0) return;
    }
  }

  /// The canonical form of `value` for `path`, made once per value: each takes a scene read
  /// or two, and a value recurs in many jobs.
  nlohmann::json canonical(const SceneDocument& base, const std::string& path,
                           const Value& value) const {
    const auto key = std::make_pair(path, value.raw.dump());
    const auto known = canonical_values_.find(key);
    if (known != canonical_values_.end()) return known->second;
    return canonical_values_[key] = base.canonical_override(path, value.raw);
  }

  /// The job at `pick`, its values made canonical and applied to the base scene, and whether
  /// its depth was set aside (a direct job's). An impossible value is reported at its line with
  /// the job's parameters; values that are possible alone but not together (e.g. an edge length
  /// and a width) at the line of the first.
  std::pair<SweepJob, bool> make_job(const SceneDocument& base, const std::string& scene_hash,
                                     const std::vector<Axis>& axes,
                                     const std::vector<std::size_t>& pick,
                                     const std::map<std::string, Value>& defaults) const {
    std::map<std::string, Value> chosen = defaults;
    for (std::size_t a = 0; a < axes.size(); ++a)
      for (std::size_t p = 0; p < axes[a].paths.size(); ++p)
        chosen[axes[a].paths[p]] = axes[a].columns[p][pick[a]];

    SweepJob job;
    auto fail_job = [&](const Value& value, const std::string& message) {
      std::string parameters;
      for (const auto& [path, v] : chosen)
        parameters += fmt::format("{}{}={}", parameters.empty() ? "" : " ", path, v.raw.dump());
      fail(value.line, fmt::format("job {}: {}", parameters, message));
    };
    for (const auto& [path, value] : chosen) {
      if (path == kDepth) {
        if (!value.raw.is_number_integer() || value.raw.get<std::int64_t>() < 1 ||
            value.raw.get<std::int64_t>() > 64)
          fail_job(value, fmt::format("'depth' must be an integer in [1, 64] (got {})",
                                      value.raw.dump()));
        job.depth = value.raw.get<int>();
        continue;
      }
      if (path == kMethod) continue;  // read once the depth is known, below
      try {
        job.overrides[path] = canonical(base, path, value);
      } catch (const OverrideError& error) {
        fail_job(value, error.what());
      }
    }
    // One override alone was read with its value by canonical(); several may clash.
    if (job.overrides.size() > 1) {
      try {
        base.apply(job.overrides);
      } catch (const OverrideError& error) {
        fail_job(chosen.at(job.overrides.begin()->first), error.what());
      }
    }
    bool depth_ignored = false;
    if (const auto method = chosen.find(kMethod); method != chosen.end()) {
      const std::optional<db::Method> named = named_method(method->second.raw);
      if (!named) fail_job(method->second, method_refusal(method->second.raw));
      job.method = *named;
      if (!db::uses_hierarchy(job.method)) depth_ignored = std::exchange(job.depth, 1) != 1;
      else if (job.depth < 2)
        fail_job(method->second,
                 fmt::format("method \"{}\" solves a hierarchy, which needs 'depth' 2 or more "
                             "(got {}); give the sweep a depth of 2 or more",
                             db::to_string(job.method), job.depth));
    } else {
      job.method = db::method_of_depth(job.depth);
    }
    job.parameters = canonical_parameters(scene_hash, job.overrides, job.depth, job.method);
    job.id = job_id(job.parameters);
    return {std::move(job), depth_ignored};
  }

  static std::vector<std::string> method_names() {
    std::vector<std::string> names;
    for (const db::Method method : db::kAllMethods) names.emplace_back(db::to_string(method));
    return names;
  }

  /// The method `value` names, if it names one.
  static std::optional<db::Method> named_method(const nlohmann::json& value) {
    const std::vector<std::string> names = method_names();
    if (!value.is_string() ||
        std::find(names.begin(), names.end(), value.get<std::string>()) == names.end())
      return std::nullopt;
    return db::method_from_string(value.get<std::string>());
  }

  /// Why `value` is not a method, with the nearest name and the valid ones.
  static std::string method_refusal(const nlohmann::json& value) {
    const std::vector<std::string> names = method_names();
    const auto nearest =
        value.is_string() ? suggest_key(value.get<std::string>(), names) : std::nullopt;
    return fmt::format("'{}' must name a method{} (got {}); valid methods: {}", kMethod,
                       nearest ? fmt::format(", did you mean \"{}\"?", *nearest) : "",
                       value.dump(), fmt::join(names, ", "));
  }

  // ---- refine: coarse-first sweeps ------------------------------------------------------------

  /// The top-level `refine`: "all" (the default), "none", or a table naming a rule.
  db::RefineRule read_refine() const {
    const toml::node* node = document_.get(kRefine);
    if (!node) return {};
    if (const auto* text = node->as_string()) {
      if (text->get() == "all") return {};
      if (text->get() == "none") return rule_of_kind(db::RefineKind::none);
      fail(line_of(*node), fmt::format("'refine' = \"{}\" is not a choice; use \"all\", \"none\" "
                                       "or a table with a rule: refine = {{ rule = \"top\", by = "
                                       "\"max_displacement\", count = 3 }}",
                                       text->get()));
    }
    const toml::table* table = node->as_table();
    if (!table)
      fail(line_of(*node), "'refine' must be \"all\", \"none\" or a table with a rule");
    return read_refine_rule(*table, line_of(*node));
  }

  db::RefineRule read_refine_rule(const toml::table& table, long line) const {
    static const std::map<std::string, std::pair<db::RefineKind, std::vector<std::string>>> rules{
        {"none", {db::RefineKind::none, {}}},
        {"top", {db::RefineKind::top, {"by", "count", "order"}}},
        {"threshold", {db::RefineKind::threshold, {"by", "above", "below"}}},
        {"pareto", {db::RefineKind::pareto, {"minimize", "maximize"}}},
        {"changed", {db::RefineKind::changed, {"by", "count", "above"}}},
    };
    const toml::node* name = table.get("rule");
    std::vector<std::string> names;
    for (const auto& [rule, kind] : rules) names.push_back(rule);
    if (!name || !name->is_string())
      fail(name ? line_of(*name) : line,
           fmt::format("'rule' in 'refine' must name a rule: {}", fmt::join(names, ", ")));
    const std::string given = *name->value<std::string>();
    const auto rule = rules.find(given);
    if (rule == rules.end()) {
      const auto nearest = suggest_key(given, names);
      fail(line_of(*name), fmt::format("unknown rule '{}' in 'refine'{}; valid rules: {}", given,
                                       nearest ? fmt::format(" (did you mean '{}'?)", *nearest) : "",
                                       fmt::join(names, ", ")));
    }
    std::vector<std::string> allowed = rule->second.second;
    allowed.insert(allowed.end(), {"rule", "preview"});
    allow_only(table, allowed, fmt::format("in 'refine' with rule = \"{}\"", given));
    db::RefineRule refine = rule_of_kind(rule->second.first);
    if (const toml::node* preview = table.get("preview"))
      refine.preview = positive_integer(*preview, "preview");
    switch (refine.kind) {
      case db::RefineKind::top:
        refine.by = required_output(table, "by", line);
        refine.count = positive_integer(required(table, "count", line), "count");
        refine.preference = read_order(table);
        break;
      case db::RefineKind::threshold:
        refine.by = required_output(table, "by", line);
        read_bound(table, "above", db::Comparison::greater, refine);
        read_bound(table, "below", db::Comparison::less, refine);
        if (refine.conditions.empty())
          fail(line, "'refine' with rule = \"threshold\" needs 'above', 'below' or both");
        break;
      case db::RefineKind::pareto:
        read_objectives(table, line, refine);
        break;
      case db::RefineKind::changed:
        refine.by = required_output(table, "by", line);
        if (table.get("count") && table.get("above"))
          fail(line, "'refine' with rule = \"changed\" takes 'count' or 'above', not both");
        if (const toml::node* count = table.get("count"))
          refine.count = positive_integer(*count, "count");
        else if (const toml::node* above = table.get("above"))
          refine.change_above = number(*above, "above");
        else
          fail(line, "'refine' with rule = \"changed\" needs 'count' (how many points) or "
                     "'above' (a relative change, e.g. 0.05)");
        break;
      default:
        break;
    }
    return refine;
  }

  static db::RefineRule rule_of_kind(db::RefineKind kind) {
    db::RefineRule rule;
    rule.kind = kind;
    return rule;
  }

  const toml::node& required(const toml::table& table, const std::string& key, long line) const {
    const toml::node* node = table.get(key);
    if (!node) fail(line, fmt::format("'refine' with this rule needs '{}'", key));
    return *node;
  }

  int positive_integer(const toml::node& node, const std::string& key) const {
    const auto* integer = node.as_integer();
    if (!integer || integer->get() < 1 || integer->get() > 64'000)
      fail(line_of(node), fmt::format("'{}' in 'refine' must be a positive integer", key));
    return static_cast<int>(integer->get());
  }

  double number(const toml::node& node, const std::string& key) const {
    if (const auto* integer = node.as_integer()) return static_cast<double>(integer->get());
    if (const auto* real = node.as_floating_point(); real && std::isfinite(real->get()))
      return real->get();
    fail(line_of(node), fmt::format("'{}' in 'refine' must be a number", key));
  }

  /// An output name, checked against what jobs record (db::kLevelOutputs).
  std::string output_name(const toml::node& node, const std::string& key) const {
    const std::vector<std::string> outputs(db::kLevelOutputs.begin(), db::kLevelOutputs.end());
    const auto name = node.value<std::string>();
    if (!node.is_string() || std::find(outputs.begin(), outputs.end(), *name) == outputs.end()) {
      const auto nearest = name ? suggest_key(*name, outputs) : std::nullopt;
      fail(line_of(node), fmt::format("'{}' in 'refine' must name an output a job records{}; "
                                      "valid outputs: {}",
                                      key,
                                      nearest ? fmt::format(" (did you mean '{}'?)", *nearest) : "",
                                      fmt::join(outputs, ", ")));
    }
    return *name;
  }

  std::string required_output(const toml::table& table, const std::string& key, long line) const {
    return output_name(required(table, key, line), key);
  }

  db::Preference read_order(const toml::table& table) const {
    const toml::node* order = table.get("order");
    if (!order) return db::Preference::largest;
    const auto text = order->value<std::string>();
    if (text == "largest") return db::Preference::largest;
    if (text == "smallest") return db::Preference::smallest;
    fail(line_of(*order), "'order' in 'refine' must be \"largest\" or \"smallest\"");
  }

  void read_bound(const toml::table& table, const std::string& key, db::Comparison op,
                  db::RefineRule& refine) const {
    if (const toml::node* bound = table.get(key))
      refine.conditions.push_back({refine.by, op, number(*bound, key)});
  }

  /// `minimize` and `maximize`: lists of outputs, two in all.
  void read_objectives(const toml::table& table, long line, db::RefineRule& refine) const {
    for (const auto& [key, preference] : {std::pair{"minimize", db::Preference::smallest},
                                          std::pair{"maximize", db::Preference::largest}}) {
      const toml::node* node = table.get(key);
      if (!node) continue;
      const toml::array* list = node->as_array();
      if (!list)
        fail(line_of(*node), fmt::format("'{}' in 'refine' must be a list of outputs", key));
      for (const toml::node& output : *list)
        refine.objectives.push_back({output_name(output, key), preference});
    }
    if (refine.objectives.size() != 2 ||
        refine.objectives[0].output == refine.objectives[1].output)
      fail(line, fmt::format("'refine' with rule = \"pareto\" needs two different outputs in "
                             "'minimize' and 'maximize' together (got {}), e.g. minimize = "
                             "[\"elastic_energy\"], maximize = [\"max_displacement\"]",
                             refine.objectives.size()));
  }

  /// Every job must have levels to preview and at least one finer level to promote to; the
  /// rule on the change between previews needs two preview levels.
  void check_refine_depths(const Sweep& sweep) const {
    if (!sweep.refine.previews()) return;
    const toml::node& node = *document_.get(kRefine);
    const toml::node* preview =
        node.is_table() ? node.as_table()->get("preview") : nullptr;
    for (const SweepJob& job : sweep.jobs) {
      const int levels = sweep.refine.preview_levels(job.levels());
      if (levels < 1 || levels >= job.levels())
        fail(line_of(preview ? *preview : node),
             fmt::format("job {}: a coarse-first job needs preview levels in [1, depth − 1], "
                         "but it solves {} level{} and has {} preview level{}; {}",
                         describe_parameters(job), job.levels(), job.levels() == 1 ? "" : "s",
                         levels, levels == 1 ? "" : "s",
                         job.levels() < 2 ? "give the sweep depth 2 or more and the method "
                                            "\"progressive\""
                                          : "lower 'preview' below the depth"));
      if (sweep.refine.kind == db::RefineKind::changed && levels < 2)
        fail(line_of(preview ? *preview : node),
             fmt::format("job {}: rule = \"changed\" compares the last two preview levels, but "
                         "the job has {} preview level; use depth 3 or more (and 'preview' of 2 "
                         "or more)",
                         describe_parameters(job), levels));
    }
  }

  fs::path file_;
  toml::table document_;
  mutable std::map<std::pair<std::string, std::string>, nlohmann::json> canonical_values_;
};

}  // namespace

Sweep read_sweep(const fs::path& file) {
  const fs::path absolute = fs::absolute(file);
  return read_sweep_text(read_input_file(absolute, "sweep file"), absolute);
}

Sweep read_sweep_text(std::string_view text, const fs::path& file) {
  return SweepReader(text, fs::absolute(file)).read();
}

std::string describe_parameters(const SweepJob& job) {
  std::string text = fmt::format("depth={} method={}", job.depth, db::to_string(job.method));
  for (const auto& [path, value] : job.overrides) text += fmt::format(" {}={}", path, value.dump());
  return text;
}

std::vector<db::NewJob> new_jobs(const Sweep& sweep) {
  std::vector<db::NewJob> jobs;
  for (const SweepJob& job : sweep.jobs)
    jobs.push_back({.id = job.id,
                    .parameters = job.parameters,
                    .scene = sweep.scene.string(),
                    .depth = job.levels(),
                    .method = job.method,
                    .preview_levels = sweep.refine.previews()
                                          ? std::optional(sweep.refine.preview_levels(job.levels()))
                                          : std::nullopt});
  return jobs;
}

}  // namespace psq::jobs
