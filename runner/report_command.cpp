// `psq report [SWEEP] --out DIR`: CSV, JSON, Markdown and a self-contained HTML page with
// plots for one sweep, or for every sweep of the store (one subdirectory each, with an
// index.html). docs/reports.md describes the files.

#include <fmt/format.h>

#include <iostream>

#include "reports/report_writer.hpp"
#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

struct ReportOptions {
  std::string sweep;
  std::string out;
  std::string database;
  std::string gnuplot = "gnuplot";
};

int run_report(const ReportOptions& options) {
  reports::ReportRequest request;
  request.database = database_path(options.database);
  if (!options.sweep.empty()) request.sweep = options.sweep;
  request.out = options.out;
  request.gnuplot = options.gnuplot;
  const reports::ReportOutcome outcome = reports::write_report(request);
  std::cout << fmt::format("report of {} sweep{} ({} jobs) written: {}\n", outcome.sweeps,
                           outcome.sweeps == 1 ? "" : "s", outcome.jobs, outcome.page.string());
  if (outcome.problems > 0)
    std::cout << fmt::format(
        "{} problem{} (unreadable checkpoints and the like) listed in the "
        "report\n",
        outcome.problems, outcome.problems == 1 ? "" : "s");
  return 0;
}

}  // namespace

void register_report_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<ReportOptions>();
  CLI::App* command = app.add_subcommand(
      "report", "Write a sweep's report: results.csv, results.json, summary.md, report.html");
  command->add_option("sweep", options->sweep,
                      "The sweep to report; every sweep of the store when omitted (one "
                      "subdirectory each, linked from index.html)");
  command
      ->add_option("--out", options->out,
                   "Report directory, written whole or not at all; an earlier report there "
                   "is replaced")
      ->required();
  command->add_option("--gnuplot", options->gnuplot, "The gnuplot program (default: from PATH)");
  add_database_option(*command, options->database);
  commands.push_back({command, [options] { return run_report(*options); }});
}

}  // namespace psq::runner
