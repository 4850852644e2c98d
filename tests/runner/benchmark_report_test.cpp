// The benchmark section of `psq report` on a real method sweep: the cantilever at two
// resolutions, every method at depth 2, run by two workers. The report's table lists every level
// of every job against the direct_final job of its resolution, and its plot is on the page; the
// error of the progressive finest level is checked against its checkpoints here.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <sstream>

#include "engine/io/checkpoint.hpp"
#include "runner/cantilever_workspace.hpp"

namespace psq {
namespace {

/// The rows of the first Markdown table after the line `heading`, as cells by column name.
std::vector<std::map<std::string, std::string>> markdown_table_after(const std::string& text,
                                                                     const std::string& heading) {
  std::istringstream lines(text.substr(text.find(heading)));
  const auto cells = [](const std::string& line) {
    std::vector<std::string> parts;
    std::istringstream row(line.substr(1));
    for (std::string cell; std::getline(row, cell, '|');)
      parts.push_back(cell.substr(1, cell.size() - 2));
    return parts;
  };
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| ", 0) != 0) {
      if (!header.empty()) break;
      continue;
    }
    if (header.empty()) {
      header = cells(line);
    } else if (line.rfind("| ---", 0) != 0) {
      const std::vector<std::string> values = cells(line);
      std::map<std::string, std::string> row;
      for (std::size_t c = 0; c < header.size() && c < values.size(); ++c)
        row[header[c]] = values[c];
      rows.push_back(row);
    }
  }
  return rows;
}

/// max_i ‖a_i − b_i‖ over the diagonal of b's bounding box: the report's error, computed here.
double relative_distance(const Positions& a, const Positions& b) {
  const double diagonal = (b.colwise().maxCoeff() - b.colwise().minCoeff()).norm();
  return (a - b).rowwise().norm().maxCoeff() / diagonal;
}

TEST(BenchmarkReport, TablesAndPlotsEveryLevelAgainstTheDirectFinalJobOfItsResolution) {
  const test::CantileverWorkspace workspace("benchmark_report");
  const test::ProcessResult added = workspace.add_sweep(
      "m",
      "method = [\"direct\", \"direct_final\", \"progressive\", \"coarse_prolonged\"]\n"
      "depth = [2]\n\"shell.strip.mesh.edge_length\" = [0.005, 0.004]\n");
  ASSERT_EQ(added.exit_code, 0) << added.errors;
  const test::ProcessResult worked = workspace.psq({"work", "--workers", "2"});
  ASSERT_EQ(worked.exit_code, 0) << worked.errors;
  const auto out = workspace.dir / "report";
  const test::ProcessResult reported = workspace.psq({"report", "m", "--out", out.string()});
  ASSERT_EQ(reported.exit_code, 0) << reported.errors;

  const std::string summary = test::read_file(out / "summary.md");
  // Every level's error to its own finest level too: a coarse-prolonged job's on the finest mesh.
  EXPECT_EQ(summary.find("## Problems"), std::string::npos) << summary;
  const auto rows = markdown_table_after(summary, "## Run time against error");
  // Per resolution: direct, direct_final and coarse_prolonged one level each, progressive two.
  ASSERT_EQ(rows.size(), 10u);
  const std::vector<db::JobResult> results = workspace.results();
  for (const auto& row : rows) {
    const db::JobResult& job = results.at(std::stoul(row.at("#")) - 1);
    if (job.job.method == db::Method::direct_final) {
      EXPECT_EQ(row.at("error to direct_final"), "0");
      EXPECT_EQ(row.at("speed-up over direct_final"), "1");
      EXPECT_EQ(row.at("Pareto front"), "yes");
    } else {
      EXPECT_GT(std::stod(row.at("error to direct_final")), 0.0) << row.at("#");
    }
    if (job.job.method == db::Method::progressive && row.at("level") == "1 of 2") {
      // The same resolution's direct_final job, and this job's finest checkpoint.
      const auto reference = std::find_if(results.begin(), results.end(), [&](const auto& r) {
        return r.job.method == db::Method::direct_final &&
               r.job.parameters["overrides"] == job.job.parameters["overrides"];
      });
      ASSERT_NE(reference, results.end());
      const double expected =
          relative_distance(read_checkpoint(job.levels.at(1).checkpoint_path).finest_positions,
                            read_checkpoint(reference->levels.at(0).checkpoint_path).positions);
      EXPECT_NEAR(std::stod(row.at("error to direct_final")), expected, 1e-3 * expected);
      // Both solve the same equilibrium on the same mesh.
      EXPECT_LT(expected, 1e-2);
    }
  }
  const std::string page = test::read_file(out / "report.html");
  EXPECT_NE(page.find("<h2>Run time against error</h2>"), std::string::npos);
  EXPECT_NE(page.find("alt=\"scene: error to direct_final of the same mesh and parameters, "
                      "against run time\" src=\"data:image/svg+xml;base64,"),
            std::string::npos);
}

}  // namespace
}  // namespace psq
