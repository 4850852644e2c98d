// `psq ccd-bench` end to end: its text and JSON reports agree with the library, and bad input
// ends with exit code 1 and a message naming the file and line.

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <regex>

#include "engine/contact/ccd_query_file.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

fs::path query_set() { return test::shared_dir() / "data" / "ccd-queries"; }

/// The library's verdict on every .csv file below `dir`.
CcdTally library_tally(const fs::path& dir, const AdditiveCcdSettings& settings = {}) {
  CcdTally tally;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.path().extension() == ".csv")
      tally +=
          tally_ccd_queries(read_ccd_queries(entry.path()), ccd_query_kind(entry.path()), settings);
  return tally;
}

nlohmann::json run_json(const std::vector<std::string>& arguments) {
  const auto result = test::run_psq(arguments);
  EXPECT_EQ(result.exit_code, 0) << result.errors;
  return nlohmann::json::parse(result.output);
}

TEST(CcdBenchCommand, JsonReportAgreesWithTheLibraryOnTheSharedSet) {
  const nlohmann::json report = run_json({"ccd-bench", query_set().string(), "--json"});
  const CcdTally expected = library_tally(query_set());
  ASSERT_EQ(report.size(), 4u) << report.dump();
  EXPECT_EQ(report["queries"].get<long>(), expected.queries);
  EXPECT_EQ(report["queries"].get<long>(), 14592 / 8);
  EXPECT_EQ(report["false_negatives"].get<long>(), 0);
  EXPECT_EQ(report["false_positives"].get<long>(), expected.false_positives);
  EXPECT_GT(report["mean_us"].get<double>(), 0.0);
  EXPECT_LT(report["mean_us"].get<double>(), 1000.0);
}

TEST(CcdBenchCommand, TextReportCarriesTheSameFigures) {
  const fs::path scene = query_set() / "erleben-spikes";
  const auto text = test::run_psq({"ccd-bench", scene.string()});
  ASSERT_EQ(text.exit_code, 0) << text.errors;
  const std::regex pattern(
      "queries: (\\d+)\nfalse negatives: (\\d+)\nfalse positives: (\\d+)\n"
      "mean time per query: ([0-9.]+) us\n");
  std::smatch figures;
  ASSERT_TRUE(std::regex_match(text.output, figures, pattern)) << text.output;
  const CcdTally expected = library_tally(scene);
  EXPECT_EQ(std::stol(figures[1]), expected.queries);
  EXPECT_EQ(std::stol(figures[2]), expected.false_negatives);
  EXPECT_EQ(std::stol(figures[3]), expected.false_positives);
  EXPECT_GT(std::stod(figures[4]), 0.0);
}

TEST(CcdBenchCommand, FilesAndSettingsFromTheCommandLine) {
  // Two files given one by one, with an iteration cap of 1: capped queries count as
  // collisions, so misses stay at zero and false alarms can only grow.
  const fs::path dir = query_set() / "erleben-sliding-spike" / "vertex-face";
  const nlohmann::json report =
      run_json({"ccd-bench", (dir / "data_0_0.csv").string(), (dir / "data_0_1.csv").string(),
                "--json", "--max-iterations", "1"});
  AdditiveCcdSettings capped;
  capped.max_iterations = 1;
  const CcdTally expected = library_tally(dir, capped);
  EXPECT_EQ(report["queries"].get<long>(), expected.queries);
  EXPECT_EQ(report["false_negatives"].get<long>(), 0);
  EXPECT_EQ(report["false_positives"].get<long>(), expected.false_positives);
  EXPECT_GT(expected.false_positives, library_tally(dir).false_positives);
}

TEST(CcdBenchCommand, MalformedFileExitsOneNamingFileAndLine) {
  const fs::path dir = test::fresh_temp_dir("ccd-bench") / "vertex-face";
  fs::create_directories(dir);
  const auto file = test::write_file(dir / "broken.csv", "1,1,2,1,3,1,0\n1,1,2,1,x,1,0\n");
  const auto result = test::run_psq({"ccd-bench", file.string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("broken.csv:2:"), std::string::npos) << result.errors;
  EXPECT_TRUE(result.output.empty()) << result.output;
}

TEST(CcdBenchCommand, FileOutsideAKindFolderOrMissingExitsOne) {
  const fs::path dir = test::fresh_temp_dir("ccd-bench");
  const auto stray = test::write_file(dir / "stray.csv", "");
  const auto outside = test::run_psq({"ccd-bench", stray.string()});
  EXPECT_EQ(outside.exit_code, 1);
  EXPECT_NE(outside.errors.find("stray.csv"), std::string::npos) << outside.errors;
  EXPECT_NE(outside.errors.find("vertex-face"), std::string::npos) << outside.errors;

  const auto missing = test::run_psq({"ccd-bench", (dir / "nothing.csv").string()});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.errors.find("nothing.csv"), std::string::npos) << missing.errors;

  fs::create_directories(dir / "empty");
  const auto empty = test::run_psq({"ccd-bench", (dir / "empty").string()});
  EXPECT_EQ(empty.exit_code, 1);
  EXPECT_NE(empty.errors.find("no .csv query files"), std::string::npos) << empty.errors;
}

TEST(CcdBenchCommand, SettingOutOfRangeExitsOne) {
  const auto result = test::run_psq({"ccd-bench", query_set().string(), "--ratio-bound", "1.5"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("ratio_bound"), std::string::npos) << result.errors;
}

}  // namespace
}  // namespace psq
