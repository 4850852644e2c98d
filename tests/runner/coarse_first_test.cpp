// Coarse-first sweeps end to end: two `psq work` processes preview every point of a small
// cantilever sweep, the rule promotes the points it should (checked here from the stored
// preview outputs), those finish bit for bit as in a refine = "all" run, the others stay
// previewed until `psq promote` selects them by hand. The main job's sweep, a contact scene,
// ends the same way.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <regex>

#include "db/job_store.hpp"
#include "engine/io/checkpoint.hpp"
#include "jobs/psq_child.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

/// Depth 3 (two preview levels), three frames, 3 thicknesses × 2 moduli: the jobs take tenths of
/// a second each.
const std::string kGrid =
    "\"shell.strip.material.thickness\" = [5e-4, 1e-3, 1.5e-3]\n"
    "\"shell.strip.material.youngs_modulus\" = [5e6, 2e7]\n"
    "\"time.frames\" = [3]\n";

/// A workspace whose sweep "cf" is the grid above with `refine` (a TOML value).
struct CoarseFirstWorkspace : test::CantileverWorkspace {
  CoarseFirstWorkspace(const std::string& name, const std::string& refine)
      : CantileverWorkspace(name) {
    const fs::path file = test::write_file(
        dir / "cf.toml",
        fmt::format("name = \"cf\"\nscene = \"scene.toml\"\ndepth = 3\nrefine = {}\n[grid]\n{}",
                    refine, kGrid));
    const test::ProcessResult added = psq({"sweep", "add", file.string()});
    EXPECT_EQ(added.exit_code, 0) << added.errors;
  }

  /// `psq work` in `processes` processes at once, one worker each; their stderr concatenated.
  std::string work(int processes) const {
    const int run = runs++;
    const auto logs_of = [&](int p) { return dir / "logs" / fmt::format("{}-{}", run, p); };
    std::vector<std::unique_ptr<test::PsqChild>> children;
    for (int p = 0; p < processes; ++p) {
      const fs::path logs = logs_of(p);
      fs::create_directories(logs);
      children.push_back(std::make_unique<test::PsqChild>(
          PSQ_EXECUTABLE, std::vector<std::string>{"work", "--db", db.string(), "--workers", "1"},
          logs));
    }
    std::string errors;
    for (int p = 0; p < processes; ++p) {
      EXPECT_EQ(children[p]->wait(), 0);
      errors += test::read_file(logs_of(p) / "child.err");
    }
    return errors;
  }

  mutable int runs = 0;
};

double preview_output(const db::JobResult& job, const std::string& output) {
  return job.levels.at(*job.job.preview_levels - 1).outputs.at(output);
}

/// The jobs a top-k rule must select, worked out here from the stored preview outputs.
std::set<std::string> expected_top(const std::vector<db::JobResult>& jobs, std::size_t k) {
  std::vector<const db::JobResult*> ranked;
  for (const db::JobResult& job : jobs) ranked.push_back(&job);
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto* a, const auto* b) {
    return preview_output(*a, "max_displacement") > preview_output(*b, "max_displacement");
  });
  std::set<std::string> ids;
  for (std::size_t i = 0; i < k; ++i) ids.insert(ranked[i]->job.id);
  return ids;
}

/// How often `pattern` (a regex with the job id as its first group) appears per job.
std::map<std::string, int> count_lines(const std::string& log, const std::string& pattern) {
  std::map<std::string, int> counts;
  const std::regex line(pattern);
  for (auto it = std::sregex_iterator(log.begin(), log.end(), line); it != std::sregex_iterator();
       ++it)
    ++counts[(*it)[1]];
  return counts;
}

/// Every level's checkpoint of `id` equals, bit for bit, the same level of the same job in
/// `reference`.
void expect_identical_levels(const CoarseFirstWorkspace& run, const CoarseFirstWorkspace& reference,
                             const std::string& id) {
  for (int level = 0; level < 3; ++level) {
    const std::string file = fmt::format("runs/{}/level_{}.h5", id, level);
    const Checkpoint ours = read_checkpoint(run.dir / file);
    const Checkpoint theirs = read_checkpoint(reference.dir / file);
    EXPECT_TRUE(ours.positions == theirs.positions) << id << " level " << level;
    EXPECT_TRUE(ours.finest_positions == theirs.finest_positions) << id << " level " << level;
    EXPECT_EQ(ours.statistics.iterations.size(), theirs.statistics.iterations.size());
  }
}

TEST(CoarseFirst, TheRulePromotesItsSelectionWhichEndsAsARefineAllRunAndTheRestWaits) {
  const CoarseFirstWorkspace coarse(
      "coarse_first", "{ rule = \"top\", by = \"max_displacement\", count = 2 }");
  const CoarseFirstWorkspace all("coarse_first_all", "\"all\"");
  const std::string log = coarse.work(2);
  all.work(1);

  const std::vector<db::JobResult> jobs = coarse.results();
  ASSERT_EQ(jobs.size(), 6u);
  const std::set<std::string> selected = expected_top(jobs, 2);
  for (const db::JobResult& job : jobs) {
    SCOPED_TRACE(job.job.id);
    ASSERT_EQ(job.job.preview_levels, 2);
    if (selected.count(job.job.id)) {
      EXPECT_EQ(job.job.state, db::JobState::done);
      EXPECT_TRUE(job.job.promoted);
      EXPECT_EQ(job.levels.size(), 3u);
      EXPECT_EQ(job.job.attempt, 2);  // one claim for the preview, one after the promotion
      expect_identical_levels(coarse, all, job.job.id);
    } else {
      EXPECT_EQ(job.job.state, db::JobState::previewed);
      EXPECT_FALSE(job.job.promoted);
      EXPECT_EQ(job.levels.size(), 2u);
      EXPECT_EQ(job.job.attempt, 1);
      EXPECT_FALSE(fs::exists(coarse.dir / "runs" / job.job.id / "level_2.h5"));
    }
  }
  // Two processes on one store: every preview ran once, every promoted job finished once.
  const auto previewed = count_lines(log, R"(job (\S+): previewed \()");
  EXPECT_EQ(previewed.size(), 6u) << log;
  for (const auto& [id, count] : previewed) EXPECT_EQ(count, 1) << id;
  const auto finished = count_lines(log, R"(job (\S+): done in )");
  EXPECT_EQ(finished.size(), 2u);
  for (const auto& [id, count] : finished) EXPECT_EQ(count, 1) << id;

  const test::ProcessResult status = coarse.psq({"status", "cf"});
  EXPECT_NE(status.output.find("done 2, failed 0, cancelled 0, previewed 4"), std::string::npos)
      << status.output;
  EXPECT_NE(status.output.find("the 2 largest by max_displacement"), std::string::npos);
  const test::ProcessResult results = coarse.psq({"results", "cf"});
  EXPECT_NE(results.output.find("previewed depth=3"), std::string::npos) << results.output;
  EXPECT_NE(results.output.find("(preview: 2 levels, promoted)"), std::string::npos);

  // The report puts every preview beside the refined answers, the selection marked.
  const test::ProcessResult report =
      coarse.psq({"report", "cf", "--out", (coarse.dir / "report").string()});
  ASSERT_EQ(report.exit_code, 0) << report.errors;
  const std::string summary = test::read_file(coarse.dir / "report" / "summary.md");
  const auto section = summary.find("## Coarse-first selection");
  ASSERT_NE(section, std::string::npos) << summary;
  const std::string table = summary.substr(section, summary.find("## Levels") - section);
  for (const db::JobResult& job : jobs) {
    const auto row = table.find(job.job.id.substr(0, 8));
    ASSERT_NE(row, std::string::npos) << table;
    const std::string line = table.substr(row, table.find('\n', row) - row);
    EXPECT_NE(line.find(selected.count(job.job.id) ? "| done | yes |" : "| previewed | no |"),
              std::string::npos)
        << line;
  }
  // The page shows every point's preview picture, and beside the selected ones their final
  // shape: 6 previews + 2 finals in the gallery.
  const std::string html = test::read_file(coarse.dir / "report" / "report.html");
  const auto gallery = html.find("Every point's preview");
  ASSERT_NE(gallery, std::string::npos);
  const std::string points = html.substr(gallery, html.find("<h2>", gallery) - gallery);
  std::size_t point_blocks = 0, selected_blocks = 0, previews = 0, finals = 0;
  for (const auto& [needle, counter] :
       std::vector<std::pair<std::string, std::size_t*>>{{"<div class=\"point", &point_blocks},
                                                         {"<div class=\"point selected", &selected_blocks},
                                                         {"of 3 (preview): ", &previews},
                                                         {"of 3 (final): ", &finals}})
    for (auto at = points.find(needle); at != std::string::npos; at = points.find(needle, at + 1))
      ++*counter;
  EXPECT_EQ(point_blocks, 6u);
  EXPECT_EQ(selected_blocks, 2u);
  // Each picture's caption appears in its <title> and its <figcaption>.
  EXPECT_EQ(previews, 2u * 6u);
  EXPECT_EQ(finals, 2u * 2u);

  // One hierarchy per attempt (a strip, no colliders): 6 preview attempts and 2 after the
  // promotion. At most the two first claims (one per process) found the cache empty.
  const auto json = nlohmann::json::parse(test::read_file(coarse.dir / "report" / "results.json"));
  const nlohmann::json& cache = json["hierarchy_cache"];
  EXPECT_EQ(cache["hits"].get<int>() + cache["builds"].get<int>(), 8) << cache;
  EXPECT_GE(cache["builds"].get<int>(), 1);
  EXPECT_LE(cache["builds"].get<int>(), 2);
  EXPECT_EQ(cache["hits_without_build"].get<int>(), 0);
  EXPECT_GT(cache["saved_seconds"].get<double>(), 0.0);
  EXPECT_NE(html.find("Hierarchy cache: " + std::to_string(cache["hits"].get<int>()) + " hits and"),
            std::string::npos);
}

TEST(CoarseFirst, TheDemoSweepRefinesTheThreeLowestHangingClothsAndPreviewsTheRest) {
  // The main job's sweep (scripts/demo.sh): a contact scene, depth 3, the top-3 rule.
  const test::CantileverWorkspace demo("coarse_first_demo");
  const test::ProcessResult added =
      demo.psq({"sweep", "add", (test::source_dir() / "jobs/sweeps/demo.toml").string()});
  ASSERT_EQ(added.exit_code, 0) << added.errors;
  const test::ProcessResult worked = demo.psq({"work", "--workers", "2"});
  ASSERT_EQ(worked.exit_code, 0) << worked.errors;

  const std::vector<db::JobResult> jobs = demo.results();
  ASSERT_EQ(jobs.size(), 9u);
  const std::set<std::string> selected = expected_top(jobs, 3);
  for (const db::JobResult& job : jobs) {
    SCOPED_TRACE(job.job.id);
    const bool refined = selected.count(job.job.id) > 0;
    EXPECT_EQ(job.job.state, refined ? db::JobState::done : db::JobState::previewed);
    ASSERT_EQ(job.levels.size(), refined ? 3u : 2u);
    for (const auto& level : job.levels)
      EXPECT_EQ(level.status, db::LevelStatus::done) << "level " << level.level;
  }
  const test::ProcessResult report =
      demo.psq({"report", "demo", "--out", (demo.dir / "report").string()});
  ASSERT_EQ(report.exit_code, 0) << report.errors;
  EXPECT_TRUE(fs::exists(demo.dir / "report" / "report.html"));
  // The six finest levels never run are the selection's doing, not records gone missing.
  const std::string summary = test::read_file(demo.dir / "report" / "summary.md");
  const auto section = summary.find("## Levels");
  ASSERT_NE(section, std::string::npos) << summary;
  const std::string levels = summary.substr(section);
  std::size_t not_refined = 0;
  for (auto at = levels.find("| not refined |"); at != std::string::npos;
       at = levels.find("| not refined |", at + 1))
    ++not_refined;
  EXPECT_EQ(not_refined, 6u) << levels;
  EXPECT_EQ(levels.find("| missing |"), std::string::npos) << levels;
}

TEST(CoarseFirst, PromoteByHandRefinesTheChosenPreviewsFromTheirCheckpoints) {
  const CoarseFirstWorkspace coarse("coarse_first_promote", "\"none\"");
  const CoarseFirstWorkspace all("coarse_first_promote_all", "\"all\"");
  coarse.work(1);
  all.work(1);
  std::vector<db::JobResult> jobs = coarse.results();
  for (const db::JobResult& job : jobs) EXPECT_EQ(job.job.state, db::JobState::previewed);

  // The smallest preview displacement, selected by a condition only it meets.
  const auto smallest = std::min_element(jobs.begin(), jobs.end(), [](const auto& a, const auto& b) {
    return preview_output(a, "max_displacement") < preview_output(b, "max_displacement");
  });
  const test::ProcessResult where = coarse.psq(
      {"promote", "cf", "--where",
       fmt::format("max_displacement <= {:.17g} and shell.strip.material.thickness > 0",
                   preview_output(*smallest, "max_displacement"))});
  ASSERT_EQ(where.exit_code, 0) << where.errors;
  EXPECT_NE(where.output.find("promoted 1 of the 6 jobs with a preview in 'cf'"), std::string::npos)
      << where.output;
  EXPECT_NE(where.output.find(smallest->job.id), std::string::npos);
  const std::string log = coarse.work(1);
  EXPECT_NE(log.find(fmt::format("job {}: resuming level 1 frame 3 from level_1.h5",
                                 smallest->job.id)),
            std::string::npos)
      << log;
  EXPECT_EQ(db::JobStore(coarse.db).find_job(smallest->job.id)->state, db::JobState::done);
  expect_identical_levels(coarse, all, smallest->job.id);

  const test::ProcessResult top =
      coarse.psq({"promote", "cf", "--top", "2", "--by", "elastic_energy", "--smallest"});
  ASSERT_EQ(top.exit_code, 0) << top.errors;
  EXPECT_NE(top.output.find("(2 selected"), std::string::npos) << top.output;
}

TEST(CoarseFirst, PromoteRefusesBadInputWithAMessage) {
  const CoarseFirstWorkspace coarse("coarse_first_bad", "\"none\"");
  const auto refused = [&](std::vector<std::string> arguments, const std::string& expected) {
    const test::ProcessResult result = coarse.psq(arguments);
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_NE(result.errors.find(expected), std::string::npos) << result.errors;
  };
  refused({"promote", "cf"}, "give --where EXPR or --top K --by OUTPUT");
  refused({"promote", "cf", "--top", "2"}, "--top K needs --by OUTPUT");
  refused({"promote", "cf", "--top", "2", "--by", "energy"}, "valid outputs: max_displacement");
  refused({"promote", "cf", "--where", "max_displacement >> 1"}, "is not a condition");
  refused({"promote", "cf", "--where", "x < 1", "--top", "1", "--by", "seconds"}, "one of them");
  refused({"promote", "nope", "--top", "1", "--by", "seconds"}, "no sweep named 'nope'");
  refused({"promote", "cf", "--top", "1", "--by", "seconds"}, "has no job with a preview yet");
  coarse.work(1);
  refused({"promote", "cf", "--where", "thicknes < 1"},
          "'thicknes' is neither an output nor a parameter");
}

}  // namespace
}  // namespace psq
