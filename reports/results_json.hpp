#pragma once
// results.json: the whole report model as JSON, for scripts.

#include <nlohmann/json.hpp>

#include "reports/report_model.hpp"

namespace psq::reports {

/// {"sweep", "source", "database", "counts": {state: n}, "swept_parameters": [...],
///  "hierarchy_cache": {"hits", "builds", "hit_seconds", "build_seconds", "saved_seconds",
///  "hits_without_build"},
///  "jobs": [{"number", "id", "parameters" (as stored), "flat_parameters", "state", "attempts",
///  "failures", "error", "outputs": {"total_seconds", "max_displacement", "elastic_energy"},
///  "problems": [...], "levels": [{"level", "status", "iterations", "seconds", "timings",
///  "final_residual", "error_to_finest", "error_to_reference", "checkpoint", "error",
///  "residuals": [...]}]}]}.
/// Values that are not known, and non-finite residuals, are null.
nlohmann::json results_json(const SweepReport& report);

}  // namespace psq::reports
