#include "reports/report_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "db/job_store.hpp"
#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "reports/html_report.hpp"
#include "reports/report_directory.hpp"
#include "reports/report_tables.hpp"
#include "reports/results_json.hpp"
#include "reports/summary_markdown.hpp"

namespace psq::reports {
namespace {

void write_text(const std::filesystem::path& file, const std::string& text) {
  write_file_atomically(file, [&](std::ostream& out) { out << text; });
}

std::size_t problem_count(const SweepReport& report) {
  std::size_t count = 0;
  for (const JobReport& job : report.jobs) count += job.problems.size();
  return count;
}

std::string counts_summary(const SweepReport& report) {
  std::string text = fmt::format("{} jobs", report.jobs.size());
  for (const auto& [state, count] : report.counts)
    if (count > 0) text += fmt::format(", {} {}", count, db::to_string(state));
  return text;
}

}  // namespace

void write_sweep_files(const SweepReport& report, const std::filesystem::path& dir,
                       Gnuplot& gnuplot) {
  write_text(dir / kResultsCsv, to_csv(results_table(report)));
  write_text(dir / kResultsJson, results_json(report).dump(2) + "\n");
  write_text(dir / kSummaryMarkdown, summary_markdown(report));
  write_text(dir / kReportHtml, html_report(report, gnuplot));
}

std::string sweep_directory_name(const std::string& sweep, std::vector<std::string>& taken) {
  std::string base;
  for (char c : sweep)
    base +=
        std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' ? c : '_';
  if (base.empty() || base.front() == '.') base = "sweep" + base;
  std::string name = base;
  for (int n = 2; std::find(taken.begin(), taken.end(), name) != taken.end(); ++n)
    name = fmt::format("{}-{}", base, n);
  taken.push_back(name);
  return name;
}

ReportOutcome write_report(const ReportRequest& request) {
  if (!std::filesystem::exists(request.database))
    throw InputError(
        fmt::format("{}: no job store here; add a sweep first (psq sweep add FILE) "
                    "or choose the store with --db or PSQ_DB",
                    request.database.string()));
  db::JobStore store(request.database);
  std::vector<std::string> sweeps;
  if (request.sweep) {
    store.status(*request.sweep);  // throws InputError for an unknown sweep, before any output
    sweeps.push_back(*request.sweep);
  } else {
    for (const db::SweepStatus& status : store.status()) sweeps.push_back(status.name);
    if (sweeps.empty())
      throw InputError(
          fmt::format("{}: the job store has no sweeps to report", request.database.string()));
  }

  ReportOutcome outcome;
  publish_directory(request.out, [&](const std::filesystem::path& dir) {
    const std::filesystem::path scratch = dir / ".gnuplot";
    std::filesystem::create_directory(scratch);
    Gnuplot gnuplot(request.gnuplot, scratch);
    std::vector<std::string> taken;
    std::vector<SweepLink> links;
    for (const std::string& sweep : sweeps) {
      const SweepReport report = gather_sweep_report(store, sweep);
      const std::string name = request.sweep ? "" : sweep_directory_name(sweep, taken);
      std::filesystem::create_directories(dir / name);
      write_sweep_files(report, dir / name, gnuplot);
      links.push_back({sweep, name + "/" + kReportHtml, counts_summary(report)});
      outcome.jobs += report.jobs.size();
      outcome.problems += problem_count(report);
    }
    if (!request.sweep) write_text(dir / kIndexHtml, html_index(links));
    std::filesystem::remove_all(scratch);
  });
  outcome.sweeps = sweeps.size();
  outcome.page = std::filesystem::absolute(request.out).lexically_normal() /
                 (request.sweep ? kReportHtml : kIndexHtml);
  return outcome;
}

}  // namespace psq::reports
