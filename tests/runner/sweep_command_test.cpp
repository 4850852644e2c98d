// `psq sweep add` and `psq status` end to end, each with its own temporary store.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "db/job_store.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

class SweepCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_temp_dir("sweep_command");
    std::filesystem::copy_file(test::source_dir() / "jobs/scenes/cantilever.toml",
                               dir_ / "scene.toml");
    db_ = dir_ / "store" / "psq.db";
  }
  std::string sweep_file(const std::string& grid, const std::string& name = "sweep.toml") {
    return test::write_file(dir_ / name, "name = \"s\"\nscene = \"scene.toml\"\n[grid]\n" + grid)
        .string();
  }
  test::ProcessResult psq(std::vector<std::string> arguments) {
    arguments.push_back("--db");
    arguments.push_back(db_.string());
    return test::run_psq(arguments);
  }
  nlohmann::json status_json() {
    const auto result = psq({"status", "--json"});
    EXPECT_EQ(result.exit_code, 0) << result.errors;
    return nlohmann::json::parse(result.output);
  }
  std::filesystem::path dir_, db_;
};

TEST_F(SweepCommand, AddsNewJobsOnceAndStatusCountsThem) {
  const auto file = sweep_file("\"time.frames\" = [3, 4]\n\"time.step\" = [0.1, 0.2]\n");
  auto first = psq({"sweep", "add", file});
  ASSERT_EQ(first.exit_code, 0) << first.errors;
  EXPECT_NE(first.output.find("sweep 's' (4 jobs): 4 added, 0 already present"), std::string::npos)
      << first.output;
  EXPECT_NE(first.output.find("depth=1 method=direct time.frames=3 time.step=0.2"), std::string::npos)
      << first.output;
  auto second = psq({"sweep", "add", file});
  ASSERT_EQ(second.exit_code, 0) << second.errors;
  EXPECT_NE(second.output.find("0 added, 4 already present"), std::string::npos) << second.output;

  const auto text = psq({"status"});
  EXPECT_EQ(text.exit_code, 0) << text.errors;
  EXPECT_NE(text.output.find("sweep 's': 4 jobs: queued 4, running 0"), std::string::npos)
      << text.output;
  const auto json = status_json();
  ASSERT_EQ(json["sweeps"].size(), 1u);
  EXPECT_EQ(json["sweeps"][0]["counts"]["queued"], 4);
  EXPECT_EQ(json["sweeps"][0]["total"], 4);
  EXPECT_EQ(json["sweeps"][0]["source"], file);
}

TEST_F(SweepCommand, DryRunShowsTheNewJobsAndWritesNothing) {
  const auto small = sweep_file("\"time.frames\" = [3]\n", "small.toml");
  auto dry = psq({"sweep", "add", small, "--dry-run"});
  ASSERT_EQ(dry.exit_code, 0) << dry.errors;
  EXPECT_NE(dry.output.find("1 would be added"), std::string::npos) << dry.output;
  EXPECT_FALSE(std::filesystem::exists(db_));  // not even created

  ASSERT_EQ(psq({"sweep", "add", small}).exit_code, 0);
  const auto extended = sweep_file("\"time.frames\" = [3, 4, 5]\n", "extended.toml");
  dry = psq({"sweep", "add", extended, "--dry-run"});
  ASSERT_EQ(dry.exit_code, 0) << dry.errors;
  EXPECT_NE(dry.output.find("2 would be added, 1 already present"), std::string::npos) << dry.output;
  EXPECT_NE(dry.output.find("time.frames=5"), std::string::npos);
  EXPECT_EQ(dry.output.find("time.frames=3"), std::string::npos);
  EXPECT_EQ(status_json()["sweeps"][0]["total"], 1);
}

TEST_F(SweepCommand, BadSweepFilesExitOneAndLeaveTheStoreAsItWas) {
  ASSERT_EQ(psq({"sweep", "add", sweep_file("\"time.frames\" = [3]\n", "good.toml")}).exit_code, 0);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"\"shell.strip.material.thickness\" = [1e-3, -1e-3]\n", ":4: job depth=1"},
      {"\"shell.strip.material.poisson_ratio\" = [0.5]\n", "(-1, 0.5)"},
      {"depth = [0]\n", "'depth' must be an integer"},
      {"\"shell.strip.material.thicknes\" = [1]\n", "did you mean"},
      {"\"shell.strip.mesh.edge_lenght\" = [0.005]\n",
       ":4: unknown parameter 'shell.strip.mesh.edge_lenght'; did you mean "
       "'shell.strip.mesh.edge_length'?"},
      {"\"shell.strip.mesh.edge_length\" = [0.05]\n",
       "'edge_length' in [shell.mesh] must be smaller than the sheet's width and height"},
      {"\"time.frames\" = [3\n", "TOML syntax error"},
  };
  for (const auto& [grid, expected] : cases) {
    const auto file = sweep_file(grid, "bad.toml");
    const auto result = psq({"sweep", "add", file});
    EXPECT_EQ(result.exit_code, 1) << grid;
    EXPECT_NE(result.errors.find("psq: error: " + file), std::string::npos) << result.errors;
    EXPECT_NE(result.errors.find(expected), std::string::npos) << result.errors;
  }
  EXPECT_EQ(status_json()["sweeps"][0]["total"], 1);
  EXPECT_TRUE(db::JobStore(db_).integrity_problems().empty());
}

TEST_F(SweepCommand, StatusListsFailuresWithTheirMessages) {
  ASSERT_EQ(psq({"sweep", "add", sweep_file("\"time.frames\" = [3, 4]\n")}).exit_code, 0);
  {
    db::JobStore store(db_);
    const auto claim = store.claim_next({"w", "host", "test"}, 60);
    ASSERT_TRUE(claim);
    store.finish(claim->lease, db::Outcome::failed_permanently, "the scene diverged at frame 2");
  }
  const auto text = psq({"status", "s"});
  EXPECT_EQ(text.exit_code, 0) << text.errors;
  EXPECT_NE(text.output.find("failed 1"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("the scene diverged at frame 2"), std::string::npos) << text.output;
  const auto json = status_json();
  ASSERT_EQ(json["sweeps"][0]["failures"].size(), 1u);
  EXPECT_EQ(json["sweeps"][0]["failures"][0]["error"], "the scene diverged at frame 2");
  EXPECT_EQ(json["sweeps"][0]["failures"][0]["parameters"]["overrides"]["time.frames"], 3);
}

TEST_F(SweepCommand, StatusRefusesAnUnknownSweepAndAMissingStore) {
  const auto missing = psq({"status"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.errors.find("no job store"), std::string::npos) << missing.errors;
  EXPECT_FALSE(std::filesystem::exists(db_));
  ASSERT_EQ(psq({"sweep", "add", sweep_file("\"time.frames\" = [3]\n")}).exit_code, 0);
  const auto unknown = psq({"status", "nope"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.errors.find("nope"), std::string::npos) << unknown.errors;
}

TEST_F(SweepCommand, TheStoreComesFromPsqDbOrDefaultsToDotPsqInTheCurrentDirectory) {
  const auto file = sweep_file("\"time.frames\" = [3]\n");
  const auto from_env = dir_ / "env" / "jobs.db";
  auto result = test::run_process("/usr/bin/env", {"PSQ_DB=" + from_env.string(),
                                                   PSQ_EXECUTABLE, "sweep", "add", file});
  EXPECT_EQ(result.exit_code, 0) << result.errors;
  EXPECT_TRUE(std::filesystem::exists(from_env));
  const auto cwd = dir_ / "cwd";
  std::filesystem::create_directories(cwd);
  result = test::run_process("/usr/bin/env", {"-u", "PSQ_DB", "-C", cwd.string(), PSQ_EXECUTABLE,
                                              "sweep", "add", file});
  EXPECT_EQ(result.exit_code, 0) << result.errors;
  EXPECT_TRUE(std::filesystem::exists(cwd / ".psq" / "psq.db"));
}

}  // namespace
}  // namespace psq
