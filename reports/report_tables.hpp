#pragma once
// The report's tables as plain text cells, built once from the model and printed as CSV,
// Markdown or HTML.

#include <string>
#include <string_view>
#include <vector>

#include "reports/report_model.hpp"

namespace psq::reports {

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  ///< each as long as the header
};

/// results.csv: one row per job — number, id, every flattened parameter, state, attempts,
/// failures, error, total seconds, max displacement, elastic energy, problems, then per level
/// l < max depth: level<l>.status, .iterations, .seconds, .residual, .error. Numbers in the
/// shortest form that reads back exactly; empty cells where there is no value.
Table results_table(const SweepReport& report);

/// The jobs at a glance: number, short id, swept parameters, state, time, max displacement,
/// elastic energy, and the failure message. Numbers with 4 significant digits.
Table jobs_table(const SweepReport& report);

/// One row per job level: number, level, status, iterations, final residual, seconds, error
/// to the finest level, checkpoint.
Table levels_table(const SweepReport& report);

/// One row per job level entered by a refinement that recorded statistics: number, level,
/// expansions, perturbation retries, CCD rounds, relaxed vertices, smallest and final gap,
/// largest and mean distance of the initializer from its prolonged target, the strain-limit
/// correction's stretch before and after, and the seconds of each phase and in all. No rows when
/// no level was refined (direct solves, or scenes without contact and strain limits).
Table refinements_table(const SweepReport& report);

/// A coarse-first sweep's previews and what became of them: number, short id, swept parameters,
/// state, whether promoted, and max displacement and elastic energy of the last preview level
/// and of the finest level. No rows for an ordinary sweep (refine = "all").
Table preview_table(const SweepReport& report);

/// Speed-ups of the hierarchy methods over the direct ones: one row per finished progressive or
/// coarse-prolonged job that has a finished direct baseline of the same scene and overrides —
/// number, short id, swept parameters, method, its time, then for the baseline `direct_final`
/// (the progressive finest level's settling schedule on the finest mesh: the honest baseline of
/// a final-frame answer) and for `direct` (every frame settled) the baseline's time and the
/// speed-up (baseline time over the job's); empty cells where that baseline is missing. No rows
/// when the sweep has no such pair.
Table speedup_table(const SweepReport& report);

/// Run time against error (benchmark_scenes): one row per level of every finished job of a
/// design point with a direct_final reference, the reference's own included — number, short id,
/// design parameters, method, level ("l of L"), the wall time up to the level, its error to the
/// reference, the speed-ups over the reference and over the design point's `direct` job (its
/// time over the level's), and "yes" when the level is on its design point's Pareto front. No
/// rows when the sweep has no reference with another job beside it.
Table benchmark_table(const SweepReport& report);

/// What the benchmark plot and table measure, for the text above them.
inline constexpr std::string_view kBenchmarkExplanation =
    "Every level of every finished job against the reference of its design point: the "
    "direct_final job of the same scene and overrides (the same mesh), the finest direct solve "
    "settled to equilibrium from the refine frame on. Error: the largest distance of a vertex of "
    "the level's answer, prolonged to the finest mesh, from the reference's, over the diagonal "
    "of the reference's bounding box; time: the wall time of the job's levels up to and "
    "including it, without the hierarchy's build. Design points of different meshes (a "
    "resolution sweep) are each measured against their own reference, and each has its own "
    "Pareto front: the levels that no other level of the point beats in both time and error. "
    "The reference itself has error 0, which the log-scale plot cannot draw: its time is in the "
    "legend entry of its front, and the table lists it.";

/// The hierarchy cache in one sentence: hits, builds, their seconds and the time the hits saved
/// (docs/reports.md).
std::string cache_summary_text(const HierarchyCacheSummary& cache);

/// RFC 4180 CSV: fields with a comma, quote or line break are quoted, quotes doubled; lines
/// end with CRLF.
std::string to_csv(const Table& table);

/// A GitHub-flavoured Markdown table (pipes escaped, line breaks as spaces).
std::string to_markdown(const Table& table);

/// "1.235e-05"-style text with 4 significant digits; empty for no value.
std::string readable_number(std::optional<double> value);

}  // namespace psq::reports
