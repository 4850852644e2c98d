// `psq results SWEEP [--csv | --json]` on a store whose jobs were run by `psq work`.

#include <gtest/gtest.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "runner/cantilever_workspace.hpp"
#include "support/run_process.hpp"

namespace psq {
namespace {

class ResultsCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    workspace_ = std::make_unique<test::CantileverWorkspace>("results_command");
    ASSERT_EQ(workspace_
                  ->add_sweep("r",
                              "\"time.frames\" = [2]\n"
                              "\"shell.strip.material.thickness\" = [1e-3, 2e-3]\n")
                  .exit_code,
              0);
    ASSERT_EQ(psq({"work", "--workers", "1"}).exit_code, 0);
  }
  static test::ProcessResult psq(std::vector<std::string> arguments) {
    return workspace_->psq(arguments);
  }
  static inline std::unique_ptr<test::CantileverWorkspace> workspace_;
};

TEST_F(ResultsCommand, CsvHasOneRowPerJobLevelWithItsParameters) {
  const auto csv = psq({"results", "r", "--csv"});
  ASSERT_EQ(csv.exit_code, 0) << csv.errors;
  std::istringstream lines(csv.output);
  std::string header, row;
  std::getline(lines, header);
  EXPECT_EQ(header,
            "job,state,depth,method,shell.strip.material.thickness,time.frames,level,level_status,"
            "iterations,final_residual,static_residual,wall_seconds,checkpoint,error");
  int rows = 0;
  for (; std::getline(lines, row); ++rows) {
    EXPECT_NE(row.find(",done,1,"), std::string::npos) << row;
    EXPECT_NE(row.find(",2,0,done,"), std::string::npos) << row;  // frames, level, status
    EXPECT_NE(row.find("level_0.h5"), std::string::npos) << row;
  }
  EXPECT_EQ(rows, 2);
  EXPECT_NE(csv.output.find(",0.001,"), std::string::npos);
  EXPECT_NE(csv.output.find(",0.002,"), std::string::npos);
}

TEST_F(ResultsCommand, JsonHasTheResidualHistories) {
  const auto json = psq({"results", "r", "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.errors;
  const auto parsed = nlohmann::json::parse(json.output);
  ASSERT_EQ(parsed["jobs"].size(), 2u);
  for (const auto& job : parsed["jobs"]) {
    EXPECT_EQ(job["state"], "done");
    ASSERT_EQ(job["levels"].size(), 1u);
    const auto& residuals = job["levels"][0]["residuals"];
    // One residual per Newton step, plus the converged check that ends each solve: at least the
    // frame's own in each of the 2 frames, then those of its settling steps.
    EXPECT_GT(residuals.size(), job["levels"][0]["iterations"].get<std::size_t>() + 2);
    for (const auto& r : residuals) EXPECT_GE(r.get<double>(), 0.0);
    // Both frames settled to equilibrium, each with its static residual.
    const auto& settled = job["levels"][0]["static_residuals"];
    ASSERT_EQ(settled.size(), 2u);
    for (int f = 0; f < 2; ++f) {
      EXPECT_EQ(settled[f][0].get<int>(), f + 1);
      EXPECT_GE(settled[f][1].get<double>(), 0.0);
    }
    EXPECT_EQ(job["levels"][0]["static_residual"], settled[1][1]);
  }
}

TEST_F(ResultsCommand, TextListsEveryJobAndUnknownSweepsAreNamed) {
  const auto text = psq({"results", "r"});
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.output.find("sweep 'r': 2 jobs"), std::string::npos) << text.output;
  const auto unknown = psq({"results", "nope"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.errors.find("no sweep named 'nope' (the store has: r)"), std::string::npos)
      << unknown.errors;
  EXPECT_EQ(psq({"results", "r", "--csv", "--json"}).exit_code, 1);
  const auto help = test::run_psq({"results", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("--csv"), std::string::npos);
}

}  // namespace
}  // namespace psq
