#pragma once
// Coarse-first sweeps (docs/sweep-format.md, "Coarse-first sweeps"): what a sweep does after
// its jobs have run their preview levels, and the selection of the points promoted to the
// finer levels. The rules read only what the store holds (each finished level's outputs), so
// the store can apply them inside the transaction that records the last preview.

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace psq::db {

/// The outputs every finished level records (levels.outputs), by which rules select: the
/// largest displacement ‖x − X‖ of the level's vertices (m), the elastic energy of its last
/// frame at the finest scale (J), its final residual ‖∇E‖, its Newton iterations and its wall
/// time (s). A solver that does not compute one leaves it out.
inline constexpr std::array<std::string_view, 5> kLevelOutputs{
    "max_displacement", "elastic_energy", "residual", "iterations", "seconds"};

/// What a sweep does after the previews. `all` runs every level of every job (no preview
/// stage); `none` stops every job at its preview and selects nothing (promote by hand); the
/// others select points by their preview outputs. `where` is `psq promote --where`'s.
enum class RefineKind { all, none, top, threshold, pareto, changed, where };

/// Which end of an output a rule prefers: the largest values, or the smallest.
enum class Preference { largest, smallest };

enum class Comparison { less, less_equal, greater, greater_equal, equal, not_equal };

/// `name op value`, `name` an output or a parameter path (or `depth`).
struct Condition {
  std::string name;
  Comparison op = Comparison::greater;
  double value = 0;
};

/// One output a Pareto rule optimizes, and in which direction.
struct Objective {
  std::string output;
  Preference preference = Preference::smallest;
};

struct RefineRule {
  RefineKind kind = RefineKind::all;
  /// Levels every job runs before the selection; empty: all but the finest (depth − 1).
  std::optional<int> preview;
  /// top and changed: the output ranked.
  std::string by;
  /// top: which values are ranked first.
  Preference preference = Preference::largest;
  /// top and changed: how many points are selected (changed: or `change_above`).
  std::optional<int> count;
  /// changed: every point whose relative change exceeds this is selected.
  std::optional<double> change_above;
  /// threshold and where: a point is selected when it meets all of them.
  std::vector<Condition> conditions;
  /// pareto: the two objectives.
  std::vector<Objective> objectives;

  /// Whether jobs stop at a preview stage (every kind but `all`).
  bool previews() const { return kind != RefineKind::all; }
  /// Whether the store applies the rule itself once the previews are in.
  bool selects() const { return kind != RefineKind::all && kind != RefineKind::none; }
  /// The preview levels of a job of `depth` levels.
  int preview_levels(int depth) const { return preview.value_or(depth - 1); }
};

/// The rule as stored in sweeps.refine; refine_rule_from_json reads it back.
nlohmann::json to_json(const RefineRule& rule);
RefineRule refine_rule_from_json(const nlohmann::json& stored);
/// One line for people: "top 3 by max_displacement (largest) after 2 preview levels".
std::string describe(const RefineRule& rule);

std::string_view to_string(RefineKind kind);
std::string_view to_string(Comparison op);

/// A job that has its preview, as a rule sees it.
struct PreviewPoint {
  std::string job_id;
  /// `depth` and every numeric override, by path.
  std::map<std::string, double> parameters;
  /// Of the last preview level.
  std::map<std::string, double> outputs;
  /// Of the preview level before it; empty when the preview has one level.
  std::map<std::string, double> earlier_outputs;
};

/// Relative change of `output` between the last two preview levels,
/// |o − o'| / max(|o|, |o'|) (0 when both are 0); empty when either level lacks it.
std::optional<double> relative_change(const PreviewPoint& point, const std::string& output);

/// The ids of the points `rule` selects, in the order of `points`. A point that lacks a
/// value the rule needs (an output the solver did not record, a level) is never selected.
/// Ties in a ranking go to the earlier point. Throws InputError for a `where` condition naming
/// neither an output nor a parameter of the points.
std::vector<std::string> select_points(const RefineRule& rule,
                                       const std::vector<PreviewPoint>& points);

}  // namespace psq::db
