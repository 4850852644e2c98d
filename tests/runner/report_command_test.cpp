// `psq report` end to end on the report fixture store: the files and their content, and bad
// input (unknown sweep, missing store, unwritable --out, a full or read-only disk) with exit 1
// and nothing written.

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include "reports/report_fixture.hpp"
#include "support/run_process.hpp"
#include "support/small_filesystem.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// The directory's entries, sorted by name.
std::vector<std::string> entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

class ReportCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_temp_dir("report_command");
    database_ = test::make_report_fixture(dir_);
  }
  test::ProcessResult psq(std::vector<std::string> arguments) {
    arguments.insert(arguments.end(), {"--db", database_.string()});
    return test::run_psq(arguments);
  }
  std::filesystem::path dir_, database_;
};

TEST_F(ReportCommand, WritesTheReportOfASweepAndPrintsItsPage) {
  const auto out = dir_ / "out";
  const auto result = psq({"report", "plates", "--out", out.string()});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  EXPECT_NE(
      result.output.find("report of 1 sweep (6 jobs) written: " + (out / "report.html").string()),
      std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("2 problems"), std::string::npos) << result.output;

  const auto json = nlohmann::json::parse(test::read_file(out / "results.json"));
  const auto jobs = test::fixture_jobs();
  ASSERT_EQ(json["jobs"].size(), jobs.size());
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    EXPECT_EQ(json["jobs"][j]["id"], jobs[j].id);
    EXPECT_EQ(json["jobs"][j]["flat_parameters"]["overrides.shell.plate.material.thickness"],
              jobs[j].thickness);
    EXPECT_EQ(json["jobs"][j]["state"], db::to_string(jobs[j].state));
  }
  EXPECT_EQ(json["jobs"][0]["levels"][0]["iterations"], jobs[0].levels[0].residuals.size());
  EXPECT_EQ(json["jobs"][0]["outputs"]["elastic_energy"], 0.125);

  const std::string csv = test::read_file(out / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7);  // header + 6 jobs
  EXPECT_NE(csv.find("\r\n3,00000000000000c3,1,0.001,1e+07,fnv1a64:00000000000000aa,done,"),
            std::string::npos)
      << csv;
  EXPECT_TRUE(std::filesystem::exists(out / "summary.md"));
  EXPECT_NE(test::read_file(out / "report.html").find("<h1>Sweep plates</h1>"),
            std::string::npos);
}

TEST_F(ReportCommand, WithoutASweepReportsEverySweep) {
  const auto out = dir_ / "all";
  const auto result = psq({"report", "--out", out.string()});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  EXPECT_NE(result.output.find((out / "index.html").string()), std::string::npos) << result.output;
  EXPECT_EQ(entries(out), (std::vector<std::string>{".psq-report", "index.html", "plates"}));
  EXPECT_TRUE(std::filesystem::exists(out / "plates" / "report.html"));
}

TEST_F(ReportCommand, AnUnknownSweepExitsOneAndWritesNothing) {
  const auto out = dir_ / "out";
  const auto result = psq({"report", "nosuch", "--out", out.string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("psq: error: "), std::string::npos) << result.errors;
  EXPECT_NE(result.errors.find("no sweep named 'nosuch' (the store has: plates)"),
            std::string::npos)
      << result.errors;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(ReportCommand, AMissingStoreExitsOne) {
  const auto result = test::run_psq(
      {"report", "plates", "--out", (dir_ / "out").string(), "--db", (dir_ / "none.db").string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("no job store"), std::string::npos) << result.errors;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "none.db"));
}

TEST_F(ReportCommand, AnUnwritableOutExitsOneAndLeavesNothingHalfWritten) {
  const std::vector<std::string> before = entries(dir_);
  // Below a regular file, no directory can be made (permissions would not stop root).
  const auto blocker = test::write_file(dir_ / "blocker", "a file");
  const auto under_file = psq({"report", "plates", "--out", (blocker / "report").string()});
  EXPECT_EQ(under_file.exit_code, 1);
  EXPECT_NE(under_file.errors.find("cannot write a report to '" + (blocker / "report").string()),
            std::string::npos)
      << under_file.errors;
  const auto onto_file = psq({"report", "plates", "--out", blocker.string()});
  EXPECT_EQ(onto_file.exit_code, 1);
  EXPECT_NE(onto_file.errors.find("it exists and is not a directory"), std::string::npos)
      << onto_file.errors;
  EXPECT_EQ(test::read_file(blocker), "a file");
  // The proc file system refuses new directories outright.
  const auto in_proc = psq({"report", "plates", "--out", "/proc/psq-report-test"});
  EXPECT_EQ(in_proc.exit_code, 1);
  EXPECT_NE(in_proc.errors.find("/proc/psq-report-test"), std::string::npos) << in_proc.errors;

  std::vector<std::string> expected = before;
  expected.push_back("blocker");
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(entries(dir_), expected);
}

TEST_F(ReportCommand, AFullOrReadOnlyDiskLeavesThePreviousReportWhole) {
  const auto disk_dir = dir_ / "disk";
  const test::SmallFilesystem disk(disk_dir, 4 << 20);
  const auto out = disk_dir / "report";
  ASSERT_EQ(psq({"report", "plates", "--out", out.string()}).exit_code, 0);
  std::map<std::string, std::string> previous;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(out))
    if (entry.is_regular_file()) previous[entry.path().string()] = test::read_file(entry.path());
  const auto expect_refused_and_kept = [&](const std::string& reason) {
    const auto result = psq({"report", "plates", "--out", out.string()});
    EXPECT_EQ(result.exit_code, 1) << result.errors;
    EXPECT_NE(result.errors.find("cannot write a report to '" + out.string() + "'"),
              std::string::npos)
        << result.errors;
    EXPECT_NE(result.errors.find(reason), std::string::npos) << result.errors;
    std::size_t files = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(out))
      if (entry.is_regular_file()) {
        ++files;
        EXPECT_EQ(test::read_file(entry.path()), previous[entry.path().string()]) << entry.path();
      }
    EXPECT_EQ(files, previous.size());
  };
  // The disk fills up in the tables, in the plots (gnuplot says nothing then) and in the page.
  for (const std::size_t spare : {0, 24 << 10, 64 << 10, 128 << 10}) {
    SCOPED_TRACE(spare);
    disk.fill(spare);
    expect_refused_and_kept("No space left on device");
    EXPECT_EQ(entries(disk_dir), (std::vector<std::string>{".filler", "report"}));
    disk.free_space();
  }
  disk.set_read_only(true);
  expect_refused_and_kept("Read-only file system");
  disk.set_read_only(false);
  EXPECT_EQ(psq({"report", "plates", "--out", out.string()}).exit_code, 0);
}

TEST_F(ReportCommand, AMissingGnuplotExitsOneWithTheFixAndWritesNothing) {
  const auto out = dir_ / "out";
  const auto result =
      psq({"report", "plates", "--out", out.string(), "--gnuplot", "/nonexistent/gnuplot"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("gnuplot-nox"), std::string::npos) << result.errors;
  EXPECT_FALSE(std::filesystem::exists(out));
  for (const std::string& name : entries(dir_))
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
}

}  // namespace
}  // namespace psq
