// write_report on the fixture store: CSV, JSON, Markdown and HTML content against the
// fixture's inputs, and the all-or-nothing output directory.

#include "reports/report_writer.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "engine/core/error.hpp"
#include "reports/report_fixture.hpp"
#include "support/test_paths.hpp"

namespace psq::reports {
namespace {

/// RFC 4180 records: quoted fields may hold commas, doubled quotes and line breaks.
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> records(1, std::vector<std::string>(1));
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    std::string& field = records.back().back();
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      records.back().emplace_back();
    } else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      ++i;
      records.emplace_back(1);
    } else {
      field += c;
    }
  }
  if (records.back() == std::vector<std::string>(1)) records.pop_back();
  return records;
}

/// The expected final residual: the last finite value of the history.
double last_finite(const std::vector<double>& residuals) {
  for (auto r = residuals.rbegin(); r != residuals.rend(); ++r)
    if (std::isfinite(*r)) return *r;
  return NAN;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

class ReportWriter : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::fresh_temp_dir("report_writer");
    database_ = test::make_report_fixture(dir_);
    outcome_ = write_report({database_, "plates", dir_ / "report", "gnuplot"});
  }
  static std::filesystem::path dir_, database_;
  static ReportOutcome outcome_;
};
std::filesystem::path ReportWriter::dir_, ReportWriter::database_;
ReportOutcome ReportWriter::outcome_;

TEST_F(ReportWriter, WritesTheFourFilesAndNothingElse) {
  EXPECT_EQ(outcome_.page, dir_ / "report" / "report.html");
  EXPECT_EQ(outcome_.sweeps, 1u);
  EXPECT_EQ(outcome_.jobs, 6u);
  EXPECT_EQ(outcome_.problems, 2u);  // job 2's corrupted and job 5's missing checkpoint
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "report"))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{".psq-report", "report.html", "results.csv",
                                             "results.json", "summary.md"}));
  for (const auto& entry : std::filesystem::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string().find(".report.tmp"), std::string::npos);
}

TEST_F(ReportWriter, CsvHasOneRowPerJobWithTheInputsAndDerivedValues) {
  const auto records = parse_csv(test::read_file(dir_ / "report" / "results.csv"));
  const auto jobs = test::fixture_jobs();
  ASSERT_EQ(records.size(), jobs.size() + 1);
  const std::vector<std::string>& header = records[0];
  const auto column = [&](const std::string& name) {
    const auto found = std::find(header.begin(), header.end(), name);
    EXPECT_NE(found, header.end()) << name;
    return static_cast<std::size_t>(found - header.begin());
  };
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    const test::FixtureJob& job = jobs[j];
    const std::vector<std::string>& row = records[j + 1];
    SCOPED_TRACE(job.id);
    ASSERT_EQ(row.size(), header.size());
    EXPECT_EQ(row[column("number")], std::to_string(j + 1));
    EXPECT_EQ(row[column("id")], job.id);
    EXPECT_EQ(row[column("state")], db::to_string(job.state));
    EXPECT_EQ(row[column("error")], job.error);
    EXPECT_EQ(std::stoi(row[column("depth")]), job.depth());
    EXPECT_EQ(std::stod(row[column("overrides.shell.plate.material.thickness")]), job.thickness);
    EXPECT_EQ(std::stod(row[column("overrides.shell.plate.material.youngs_modulus")]),
              job.youngs_modulus);
    EXPECT_EQ(row[column("scene")], "fnv1a64:00000000000000aa");
    if (job.state == db::JobState::queued) {
      EXPECT_EQ(row[column("level0.status")], "missing");
      continue;
    }
    const double diagonal = std::sqrt(2.0 + job.bend * job.bend);
    double total = 0;
    for (int l = 0; l < job.depth(); ++l) {
      const test::FixtureLevel& level = job.levels[l];
      const std::string prefix = "level" + std::to_string(l) + ".";
      EXPECT_EQ(row[column(prefix + "status")], db::to_string(level.status));
      EXPECT_EQ(std::stoul(row[column(prefix + "iterations")]), level.residuals.size());
      EXPECT_EQ(std::stod(row[column(prefix + "residual")]), last_finite(level.residuals));
      EXPECT_EQ(std::stod(row[column(prefix + "static_residual")]),
                test::fixture_static_residual(l));
      EXPECT_DOUBLE_EQ(std::stod(row[column(prefix + "seconds")]), level.expected_seconds);
      total += level.expected_seconds;
      const std::string error = row[column(prefix + "error")];
      const bool comparable = job.state == db::JobState::done && job.id != "00000000000000b2" &&
                              job.id != "00000000000000e5";
      if (comparable) {
        EXPECT_NEAR(std::stod(error), level.lift / diagonal, 1e-15) << prefix;
      } else {
        EXPECT_EQ(error, "") << prefix;  // no finest level to compare with, or not finished
      }
    }
    if (job.state == db::JobState::done) {
      EXPECT_DOUBLE_EQ(std::stod(row[column("total_seconds")]), total);
    }
    if (job.id == "00000000000000a1" || job.id == "00000000000000c3") {
      EXPECT_NEAR(std::stod(row[column("max_displacement")]), job.bend, 1e-15);
      EXPECT_EQ(std::stod(row[column("elastic_energy")]), *job.elastic_energy);
      EXPECT_EQ(row[column("problems")], "");
    }
  }
  // Jobs of depth 1 leave the level-1 and level-2 columns empty.
  EXPECT_EQ(records[3][column("level1.status")], "");
  EXPECT_NE(records[2][column("problems")].find("level 1:"), std::string::npos);
  EXPECT_NE(records[5][column("problems")].find("level 0:"), std::string::npos);
}

TEST_F(ReportWriter, JsonHoldsEveryJobWithItsLevelsAndResidualHistories) {
  const auto json = nlohmann::json::parse(test::read_file(dir_ / "report" / "results.json"));
  const auto jobs = test::fixture_jobs();
  EXPECT_EQ(json["sweep"], "plates");
  EXPECT_EQ(json["source"], "sweeps/plates.toml");
  EXPECT_EQ(json["counts"]["done"], 4);
  EXPECT_EQ(json["counts"]["failed"], 1);
  EXPECT_EQ(json["counts"]["queued"], 1);
  EXPECT_EQ(json["swept_parameters"],
            nlohmann::json({"depth", "overrides.shell.plate.material.thickness",
                            "overrides.shell.plate.material.youngs_modulus"}));
  ASSERT_EQ(json["jobs"].size(), jobs.size());
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    const nlohmann::json& job = json["jobs"][j];
    SCOPED_TRACE(jobs[j].id);
    EXPECT_EQ(job["id"], jobs[j].id);
    EXPECT_EQ(job["parameters"], jobs[j].parameters());
    EXPECT_EQ(job["state"], db::to_string(jobs[j].state));
    ASSERT_EQ(job["levels"].size(), static_cast<std::size_t>(jobs[j].depth()));
    if (jobs[j].state == db::JobState::queued) continue;
    for (int l = 0; l < jobs[j].depth(); ++l) {
      const nlohmann::json& residuals = job["levels"][l]["residuals"];
      const std::vector<double>& expected = jobs[j].levels[l].residuals;
      ASSERT_EQ(residuals.size(), expected.size());
      for (std::size_t i = 0; i < expected.size(); ++i) {
        if (std::isnan(expected[i])) {
          EXPECT_TRUE(residuals[i].is_null());
        } else {
          EXPECT_EQ(residuals[i].get<double>(), expected[i]);
        }
      }
      EXPECT_EQ(job["levels"][l]["error"], jobs[j].levels[l].error);
    }
  }
  EXPECT_EQ(json["jobs"][3]["error"], "Newton diverged at frame 3");
  EXPECT_EQ(json["jobs"][3]["outputs"]["max_displacement"], nullptr);
  EXPECT_NEAR(json["jobs"][0]["levels"][1]["error_to_finest"].get<double>(), 0.01 / std::sqrt(2.04),
              1e-15);
  EXPECT_EQ(json["jobs"][1]["problems"].size(), 1u);
  // Job 1's finest frames, from the store: probes in name order.
  const nlohmann::json& frames = json["jobs"][0]["levels"][2]["frames"];
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1]["frame"], 2);
  EXPECT_EQ(frames[1]["load_scale"], 1.0);
  EXPECT_EQ(frames[1]["probes"][0],
            nlohmann::json({{"name", "clamp"}, {"kind", "reaction"}, {"value", {0, 0, -4}}}));
  EXPECT_TRUE(json["jobs"][0]["levels"][0]["frames"].empty());
}

TEST_F(ReportWriter, MarkdownSummaryHasTheTablesAndTheProblems) {
  const std::string markdown = test::read_file(dir_ / "report" / "summary.md");
  EXPECT_NE(markdown.find("# Sweep plates"), std::string::npos);
  EXPECT_NE(markdown.find("| done | 4 |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| 4 | 00000000 | 2 | 0.002 | 1e+07 | failed |"), std::string::npos)
      << markdown;
  EXPECT_NE(markdown.find("Newton diverged at frame 3"), std::string::npos);
  EXPECT_NE(markdown.find("| 1 | 2 | done | 5 | 3e-08 | 3e-07 | 6 | 0 |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("- job #2 (00000000000000b2): level 1:"), std::string::npos);
  EXPECT_NE(markdown.find("- job #5 (00000000000000e5): level 0:"), std::string::npos);
  EXPECT_EQ(count(markdown, "\n| --- |"), 3u);  // counts, jobs, levels
}

TEST_F(ReportWriter, HtmlHasEveryPlotAndPictureAndNoNetworkReference) {
  const std::string html = test::read_file(dir_ / "report" / "report.html");
  // Plots: time per level, error against run time, the 3 outputs against the thickness (the
  // swept parameter with the most values among finished jobs), and one convergence plot per
  // level with a readable checkpoint of a finished job: 3 (job 1) + 1 (job 2, level 0) + 1
  // (job 3), and one per probe of job 1's finest level (2). Pictures: those 5 levels, each job's
  // with one colour bar; job 3's collider is drawn from its part-meshes file.
  EXPECT_EQ(count(html, "<img "), 1u + 1u + 3u + 5u + 2u);
  EXPECT_EQ(count(html, "src=\"data:image/svg+xml;base64,"), 12u);
  EXPECT_NE(html.find("alt=\"job #1: probe &#39;tip&#39; against the load scale\""),
            std::string::npos);
  EXPECT_NE(html.find("alt=\"job #1: probe &#39;clamp&#39; against the load scale\""),
            std::string::npos);
  EXPECT_EQ(count(html, "<svg class=\"shape\""), 5u);
  EXPECT_EQ(count(html, "<svg class=\"colour-bar\""), 3u);
  EXPECT_EQ(count(html, "class=\"collider\""), static_cast<std::size_t>(test::kColliderTriangles));
  EXPECT_NE(html.find("job #1, level 0 of 3 (preview)"), std::string::npos);
  EXPECT_NE(html.find("job #1, level 2 of 3 (final)"), std::string::npos);
  EXPECT_NE(html.find("alt=\"max displacement against thickness\""), std::string::npos);
  EXPECT_NE(html.find("alt=\"job #1, level 1: residual in each Newton solve\""),
            std::string::npos);
  EXPECT_NE(html.find("Hierarchy cache: not used"), std::string::npos);
  EXPECT_EQ(count(html, "http:"), 0u);
  EXPECT_EQ(count(html, "https:"), 0u);
  EXPECT_EQ(count(html, "<h2 id=\"job-"), 4u);  // the finished jobs have sections
  EXPECT_EQ(html.find("id=\"job-4\""), std::string::npos);
  EXPECT_NE(html.find("Newton diverged at frame 3"), std::string::npos);
  EXPECT_NE(html.find("<li>job #2 (<code>00000000000000b2</code>): level 1:"), std::string::npos);
}

TEST_F(ReportWriter, ReplacesAnEarlierReportWhole) {
  const auto out = dir_ / "again";
  write_report({database_, "plates", out, "gnuplot"});
  test::write_file(out / "stray.txt", "left from before");
  std::filesystem::remove(out / "summary.md");
  write_report({database_, "plates", out, "gnuplot"});
  EXPECT_FALSE(std::filesystem::exists(out / "stray.txt"));
  EXPECT_TRUE(std::filesystem::exists(out / "summary.md"));
  EXPECT_EQ(test::read_file(out / "results.csv"),
            test::read_file(dir_ / "report" / "results.csv"));
}

TEST_F(ReportWriter, AFailureLeavesNoHalfReportAndKeepsTheEarlierOne) {
  const auto fresh = dir_ / "never";
  EXPECT_THROW(write_report({database_, "plates", fresh, "false"}), Error);
  EXPECT_FALSE(std::filesystem::exists(fresh));
  const auto earlier = dir_ / "earlier";
  write_report({database_, "plates", earlier, "gnuplot"});
  const std::string before = test::read_file(earlier / "report.html");
  EXPECT_THROW(write_report({database_, "plates", earlier, "/nonexistent/gnuplot"}), InputError);
  EXPECT_EQ(test::read_file(earlier / "report.html"), before);
  for (const auto& entry : std::filesystem::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
}

TEST_F(ReportWriter, RefusesToReplaceADirectoryItDidNotWrite) {
  const auto mine = dir_ / "mine";
  std::filesystem::create_directories(mine);
  test::write_file(mine / "notes.txt", "precious");
  try {
    write_report({database_, "plates", mine, "gnuplot"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("refusing to replace"), std::string::npos) << e.what();
  }
  EXPECT_EQ(test::read_file(mine / "notes.txt"), "precious");
  EXPECT_FALSE(std::filesystem::exists(mine / "report.html"));
}

TEST_F(ReportWriter, AnUnknownSweepIsAnInputError) {
  try {
    write_report({database_, "plate", dir_ / "unknown", "gnuplot"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no sweep named 'plate'"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir_ / "unknown"));
}

TEST_F(ReportWriter, EverySweepGoesToItsOwnDirectoryWithAnIndex) {
  {
    db::JobStore store(database_);
    store.add_sweep(
        "plates again/2", "other.toml",
        {{"00000000000000a1", test::fixture_jobs()[0].parameters(), "plates.toml", 3,
          db::Method::progressive, 1}});
  }
  const auto out = dir_ / "all";
  const ReportOutcome outcome = write_report({database_, std::nullopt, out, "gnuplot"});
  EXPECT_EQ(outcome.sweeps, 2u);
  EXPECT_EQ(outcome.page, out / "index.html");
  EXPECT_TRUE(std::filesystem::exists(out / "plates" / "report.html"));
  EXPECT_TRUE(std::filesystem::exists(out / "plates_again_2" / "results.csv"));
  const std::string index = test::read_file(out / "index.html");
  EXPECT_NE(index.find("<a href=\"plates_again_2/report.html\">plates again/2</a>"),
            std::string::npos)
      << index;
  const auto shared =
      nlohmann::json::parse(test::read_file(out / "plates_again_2" / "results.json"));
  ASSERT_EQ(shared["jobs"].size(), 1u);
  EXPECT_EQ(shared["jobs"][0]["state"], "done");  // the job is shared, with its results
}

TEST(SweepDirectoryName, IsSafeAndUnique) {
  std::vector<std::string> taken;
  EXPECT_EQ(sweep_directory_name("demo", taken), "demo");
  EXPECT_EQ(sweep_directory_name("demo", taken), "demo-2");
  EXPECT_EQ(sweep_directory_name("../x y", taken), "sweep.._x_y");
  EXPECT_EQ(sweep_directory_name("", taken), "sweep");
}

}  // namespace
}  // namespace psq::reports
