#include "reports/summary_markdown.hpp"

#include <fmt/format.h>

#include "reports/report_tables.hpp"

namespace psq::reports {

std::string summary_markdown(const SweepReport& report) {
  std::string text = fmt::format("# Sweep {}\n\nSweep file: `{}`  \nJob store: `{}`\n\n",
                                 report.name, report.source, report.database.string());
  Table counts{{"state", "jobs"}, {}};
  for (const auto& [state, count] : report.counts)
    counts.rows.push_back({std::string(db::to_string(state)), std::to_string(count)});
  text += to_markdown(counts);
  text += "\n" + cache_summary_text(report.hierarchy_cache) + "\n";
  text += "\n## Jobs\n\n" + to_markdown(jobs_table(report));
  if (const Table previews = preview_table(report); !previews.rows.empty())
    text += fmt::format("\n## Coarse-first selection\n\n{}\n\n{}", db::describe(report.refine),
                        to_markdown(previews));
  if (const Table speedups = speedup_table(report); !speedups.rows.empty())
    text += "\n## Speed-ups over the direct solves\n\n" + to_markdown(speedups);
  if (const Table benchmark = benchmark_table(report); !benchmark.rows.empty())
    text += fmt::format("\n## Run time against error\n\n{}\n\n{}", kBenchmarkExplanation,
                        to_markdown(benchmark));
  text += "\n## Levels\n\n" + to_markdown(levels_table(report));
  if (const Table refinements = refinements_table(report); !refinements.rows.empty())
    text += "\n## Refinements\n\n" + to_markdown(refinements);
  std::string problems;
  for (const JobReport& job : report.jobs)
    for (const std::string& problem : job.problems)
      problems += fmt::format("- job #{} ({}): {}\n", job.number, job.job.id, problem);
  if (!problems.empty()) text += "\n## Problems\n\n" + problems;
  return text;
}

}  // namespace psq::reports
