// `psq promote SWEEP --where EXPR | --top K --by OUTPUT [--smallest]`: promotes previewed jobs
// of a coarse-first sweep by hand; `psq work` then refines them from their preview checkpoints.

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <iostream>

#include "db/job_store.hpp"
#include "engine/scene/key_suggestion.hpp"
#include "runner/commands.hpp"
#include "runner/where_expression.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

struct PromoteOptions {
  std::string sweep;
  std::string database;
  std::string where;
  int top = 0;
  std::string by;
  bool smallest = false;
};

void check_output(const std::string& name) {
  const std::vector<std::string> outputs(db::kLevelOutputs.begin(), db::kLevelOutputs.end());
  if (std::find(outputs.begin(), outputs.end(), name) != outputs.end()) return;
  const auto nearest = suggest_key(name, outputs);
  throw InputError(fmt::format("--by '{}' is not an output a job records{}; valid outputs: {}",
                               name, nearest ? fmt::format(" (did you mean '{}'?)", *nearest) : "",
                               fmt::join(outputs, ", ")));
}

/// The selection the options ask for: exactly one of --where and --top (with --by).
db::RefineRule requested_rule(const PromoteOptions& options) {
  const bool where = !options.where.empty();
  const bool top = options.top > 0;
  if (where == top)
    throw InputError("psq promote: give --where EXPR or --top K --by OUTPUT (one of them)");
  db::RefineRule rule;
  if (where) {
    if (!options.by.empty() || options.smallest)
      throw InputError("psq promote: --by and --smallest go with --top, not with --where");
    rule.kind = db::RefineKind::where;
    rule.conditions = parse_where(options.where);
    return rule;
  }
  if (options.by.empty()) throw InputError("psq promote: --top K needs --by OUTPUT");
  check_output(options.by);
  rule.kind = db::RefineKind::top;
  rule.by = options.by;
  rule.count = options.top;
  rule.preference = options.smallest ? db::Preference::smallest : db::Preference::largest;
  return rule;
}

int run_promote(const PromoteOptions& options) {
  const db::RefineRule rule = requested_rule(options);
  const std::filesystem::path database = database_path(options.database);
  require_database(database);
  db::JobStore store(database);
  const db::Promotion promotion = store.promote(options.sweep, rule);
  if (promotion.candidates == 0)
    throw InputError(fmt::format(
        "sweep '{}' has no job with a preview yet: promote selects among the jobs a coarse-first "
        "sweep (refine = \"none\" or a rule, docs/sweep-format.md) stopped at their preview; run "
        "psq work first",
        options.sweep));
  std::cout << fmt::format(
      "promoted {} of the {} jobs with a preview in '{}' ({} selected, {} already promoted){}\n",
      promotion.promoted.size(), promotion.candidates, options.sweep, promotion.selected.size(),
      promotion.selected.size() - promotion.promoted.size(),
      promotion.promoted.empty() ? "" : "; run psq work to refine them");
  for (const std::string& id : promotion.promoted) std::cout << "  + " << id << '\n';
  return 0;
}

}  // namespace

void register_promote_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<PromoteOptions>();
  CLI::App* command = app.add_subcommand(
      "promote", "Promote previewed jobs of a coarse-first sweep to their finer levels");
  command->add_option("sweep", options->sweep, "Sweep name")->required();
  command->add_option("--where", options->where,
                      "Conditions on outputs and parameters: 'max_displacement > 0.002 and "
                      "shell.strip.material.thickness <= 0.001'");
  command->add_option("--top", options->top, "Promote the K best previews by --by")
      ->check(CLI::PositiveNumber);
  command->add_option("--by", options->by,
                      "Output ranked by --top: max_displacement, elastic_energy, residual, "
                      "iterations, seconds");
  command->add_flag("--smallest", options->smallest, "With --top: the smallest values first");
  add_database_option(*command, options->database);
  commands.push_back({command, [options] { return run_promote(*options); }});
}

}  // namespace psq::runner
