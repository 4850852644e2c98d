#pragma once
// summary.md: the sweep's counts, jobs and levels as Markdown tables, and its problems.

#include <string>

#include "reports/report_model.hpp"

namespace psq::reports {

/// The Markdown summary of a sweep report.
std::string summary_markdown(const SweepReport& report);

}  // namespace psq::reports
