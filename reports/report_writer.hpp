#pragma once
// `psq report`: the report files of one sweep, or of every sweep of a job store, written as
// one directory that appears whole or not at all.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "reports/gnuplot.hpp"
#include "reports/report_model.hpp"

namespace psq::reports {

/// File names inside a sweep's report directory.
inline constexpr const char* kResultsCsv = "results.csv";
inline constexpr const char* kResultsJson = "results.json";
inline constexpr const char* kSummaryMarkdown = "summary.md";
inline constexpr const char* kReportHtml = "report.html";
/// In a report of every sweep: the page that links the sweeps' reports.
inline constexpr const char* kIndexHtml = "index.html";

struct ReportRequest {
  std::filesystem::path database;  ///< the job store; must exist
  /// The sweep to report; empty: every sweep of the store, each in a subdirectory named after
  /// it (characters other than letters, digits, '.', '_' and '-' replaced by '_'), with
  /// index.html linking them.
  std::optional<std::string> sweep;
  std::filesystem::path out;        ///< the report directory (replaced if it is an earlier report)
  std::string gnuplot = "gnuplot";  ///< the gnuplot program, looked up in PATH unless a path
};

/// What was written.
struct ReportOutcome {
  std::filesystem::path page;  ///< report.html of the sweep, or index.html of all sweeps
  std::size_t sweeps = 0;
  std::size_t jobs = 0;
  std::size_t problems = 0;  ///< unreadable checkpoints and the like, shown in the report
};

/// Writes results.csv, results.json, summary.md and report.html of `report` into `dir`.
void write_sweep_files(const SweepReport& report, const std::filesystem::path& dir,
                       Gnuplot& gnuplot);

/// A directory name for a sweep, unique among `taken` (which it joins).
std::string sweep_directory_name(const std::string& sweep, std::vector<std::string>& taken);

/// Gathers and writes the requested report. Throws InputError for a missing store, an unknown
/// sweep, an output directory that cannot be written or replaced, or a missing gnuplot; then
/// nothing is left at `out` (an earlier report there stays as it was).
ReportOutcome write_report(const ReportRequest& request);

}  // namespace psq::reports
