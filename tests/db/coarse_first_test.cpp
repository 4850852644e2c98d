// Coarse-first sweeps in the store: the rules' selections on hand-made previews, the promotion
// that the last preview of a sweep triggers in its own transaction, and promotion by hand.

#include <gtest/gtest.h>

#include <algorithm>

#include "db/job_store.hpp"
#include "db/refine_rule.hpp"
#include "engine/core/error.hpp"
#include "child_process.hpp"
#include "store_fixtures.hpp"
#include "support/test_paths.hpp"

namespace psq::db {
namespace {

PreviewPoint point(std::string id, std::map<std::string, double> outputs,
                   std::map<std::string, double> earlier = {}) {
  return {std::move(id), {{"depth", 3}, {"thickness", 1e-3}}, std::move(outputs),
          std::move(earlier)};
}

RefineRule rule_of(RefineKind kind) {
  RefineRule rule;
  rule.kind = kind;
  return rule;
}

using Ids = std::vector<std::string>;

TEST(RefineRules, TopRanksByTheOutputTiesToTheEarlierAndSkipsPointsWithoutIt) {
  const std::vector<PreviewPoint> points{point("a", {{"max_displacement", 1}}),
                                         point("b", {{"max_displacement", 3}}),
                                         point("c", {{"elastic_energy", 9}}),
                                         point("d", {{"max_displacement", 3}})};
  RefineRule top = rule_of(RefineKind::top);
  top.by = "max_displacement";
  top.count = 2;
  EXPECT_EQ(select_points(top, points), (Ids{"b", "d"}));
  top.preference = Preference::smallest;
  EXPECT_EQ(select_points(top, points), (Ids{"a", "b"}));
  top.count = 10;
  EXPECT_EQ(select_points(top, points), (Ids{"a", "b", "d"}));
}

TEST(RefineRules, ThresholdParetoAndChangeSelectWhatTheyPromise) {
  const std::vector<PreviewPoint> points{
      point("a", {{"max_displacement", 1}, {"elastic_energy", 1}}, {{"max_displacement", 2}}),
      point("b", {{"max_displacement", 2}, {"elastic_energy", 3}}, {{"max_displacement", 2.1}}),
      point("c", {{"max_displacement", 3}, {"elastic_energy", 2}}, {{"max_displacement", 3}}),
      point("d", {{"max_displacement", 3}, {"elastic_energy", 5}})};
  RefineRule threshold = rule_of(RefineKind::threshold);
  threshold.conditions = {{"max_displacement", Comparison::greater, 1.5},
                          {"max_displacement", Comparison::less, 2.5}};
  EXPECT_EQ(select_points(threshold, points), (Ids{"b"}));

  // Large displacement at small energy: c dominates b and d; a is best in energy.
  RefineRule pareto = rule_of(RefineKind::pareto);
  pareto.objectives = {{"max_displacement", Preference::largest},
                       {"elastic_energy", Preference::smallest}};
  EXPECT_EQ(select_points(pareto, points), (Ids{"a", "c"}));

  // Relative changes: a 0.5, b ~0.048, c 0; d has one preview level.
  RefineRule changed = rule_of(RefineKind::changed);
  changed.by = "max_displacement";
  changed.count = 2;
  EXPECT_EQ(select_points(changed, points), (Ids{"a", "b"}));
  changed.count.reset();
  changed.change_above = 0.1;
  EXPECT_EQ(select_points(changed, points), (Ids{"a"}));
}

TEST(RefineRules, WhereConditionsMixOutputsAndParametersAndRefuseUnknownNames) {
  const std::vector<PreviewPoint> points{point("a", {{"max_displacement", 1}}),
                                         point("b", {{"max_displacement", 3}})};
  RefineRule where = rule_of(RefineKind::where);
  where.conditions = {{"max_displacement", Comparison::greater_equal, 2},
                      {"thickness", Comparison::equal, 1e-3}};
  EXPECT_EQ(select_points(where, points), (Ids{"b"}));
  where.conditions = {{"thicknes", Comparison::less, 1}};
  try {
    select_points(where, points);
    FAIL() << "an unknown name was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("'thicknes' is neither an output nor a parameter"),
              std::string::npos);
    EXPECT_NE(std::string(error.what()).find("thickness"), std::string::npos) << error.what();
  }
}

TEST(RefineRules, StoredFormReadsBackToTheSameRule) {
  RefineRule rule = rule_of(RefineKind::pareto);
  rule.preview = 2;
  rule.objectives = {{"max_displacement", Preference::largest},
                     {"seconds", Preference::smallest}};
  const RefineRule back = refine_rule_from_json(to_json(rule));
  EXPECT_EQ(to_json(back), to_json(rule));
  EXPECT_EQ(back.preview_levels(5), 2);
  EXPECT_EQ(rule_of(RefineKind::none).preview_levels(3), 2);
}

/// Claims the next job of `store` and records its levels [0, levels) with max_displacement
/// `value` (level 0 half of it), then ends the attempt as `outcome`.
std::string run_next_job(JobStore& store, double value, int levels, Outcome outcome) {
  const auto claim = store.claim_next(test::worker("w"), 30);
  EXPECT_TRUE(claim);
  for (int level = 0; level < levels; ++level) {
    LevelRecord record;
    record.level = level;
    record.status = LevelStatus::done;
    record.checkpoint_path = fmt::format("/runs/{}/level_{}.h5", claim->job.id, level);
    record.checkpoint_checksum = "fnv1a64:0000000000000001";
    record.outputs = {{"max_displacement", level + 1 == levels ? value : value / 2}};
    store.record_level(claim->lease, record);
  }
  store.finish(claim->lease, outcome);
  return claim->job.id;
}

/// A store with the coarse-first sweep "s" of `count` jobs of depth 3 (two preview levels).
struct CoarseFirstStore {
  std::filesystem::path path = psq::test::fresh_temp_dir("db-coarse") / "psq.db";
  test::ManualClock clock;
  JobStore store{path, clock.options()};

  CoarseFirstStore(int count, const RefineRule& rule) {
    std::vector<NewJob> jobs = test::thickness_jobs(0, count);
    for (NewJob& job : jobs) job.preview_levels = rule.preview_levels(job.depth);
    store.add_sweep("s", "s.toml", jobs, rule);
  }

  std::string run_next(double value, int levels, Outcome outcome) {
    return run_next_job(store, value, levels, outcome);
  }

  Job job(const std::string& id) { return *store.find_job(id); }
};

RefineRule top_two() {
  RefineRule rule = rule_of(RefineKind::top);
  rule.by = "max_displacement";
  rule.count = 2;
  return rule;
}

TEST(CoarseFirstStore, TheLastPreviewPromotesTheSelectionAndOnlyItIsClaimedAgain) {
  CoarseFirstStore s(4, top_two());
  const std::vector<double> values{0.3, 0.1, 0.4, 0.2};
  std::vector<std::string> ids;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const auto claim_levels = s.store.find_job(test::thickness_jobs(0, 4)[i].id)->levels_to_run();
    EXPECT_EQ(claim_levels, 2);
    ids.push_back(s.run_next(values[i], 2, Outcome::previewed));
    // Nothing is promoted while previews are still to come.
    if (i + 1 < values.size()) {
      EXPECT_EQ(s.job(ids[i]).state, JobState::previewed);
    }
  }
  EXPECT_EQ(s.job(ids[0]).state, JobState::queued);
  EXPECT_TRUE(s.job(ids[0]).promoted);
  EXPECT_EQ(s.job(ids[2]).state, JobState::queued);
  EXPECT_EQ(s.job(ids[1]).state, JobState::previewed);
  EXPECT_EQ(s.job(ids[3]).state, JobState::previewed);
  EXPECT_EQ(s.store.status("s").counts.at(JobState::previewed), 2);

  // The promoted jobs run all three levels; the rule applied again selects nothing new.
  const auto first = s.store.claim_next(test::worker("w"), 30);
  const auto second = s.store.claim_next(test::worker("w"), 30);
  ASSERT_TRUE(first && second);
  EXPECT_EQ(first->job.id, ids[0]);
  EXPECT_EQ(first->job.levels_to_run(), 3);
  EXPECT_EQ(second->job.id, ids[2]);
  EXPECT_FALSE(s.store.claim_next(test::worker("w"), 30));
  EXPECT_TRUE(s.store.promote("s", top_two()).promoted.empty());
}

TEST(CoarseFirstStore, AKillInsideTheLastPreviewsTransactionLosesNeitherPreviewNorPromotion) {
  CoarseFirstStore s(2, top_two());
  const std::string first = s.run_next(0.3, 2, Outcome::previewed);
  test::Pipe inside;
  test::ChildProcess doomed([&] {
    JobStoreOptions options = s.clock.options();
    options.inside_finish_transaction = [&] {
      inside.signal();
      ::pause();
    };
    JobStore store(s.path, options);
    run_next_job(store, 0.1, 2, Outcome::previewed);
  });
  ASSERT_TRUE(inside.await());
  doomed.kill_and_wait();
  // The preview's end and its promotion were one transaction: both rolled back.
  EXPECT_EQ(s.job(first).state, JobState::previewed);
  EXPECT_FALSE(s.job(first).promoted);
  EXPECT_EQ(s.store.status("s").counts.at(JobState::running), 1);
  EXPECT_TRUE(s.store.integrity_problems().empty());
  // Its lease expires; the job (with its recorded levels: progress) is run again, and its end
  // promotes the selection.
  s.clock.now += 60;
  const std::string second = s.run_next(0.1, 2, Outcome::previewed);
  EXPECT_NE(second, first);
  EXPECT_EQ(s.job(second).attempt, 2);
  EXPECT_EQ(s.job(second).failures, 0);
  EXPECT_EQ(s.job(first).state, JobState::queued);
  EXPECT_EQ(s.job(second).state, JobState::queued);
}

TEST(CoarseFirstStore, AFailedLastPreviewStillSettlesTheSweep) {
  CoarseFirstStore s(3, top_two());
  const std::string a = s.run_next(0.3, 2, Outcome::previewed);
  const std::string b = s.run_next(0.1, 2, Outcome::previewed);
  s.run_next(0.0, 0, Outcome::failed_permanently);
  EXPECT_EQ(s.job(a).state, JobState::queued);
  EXPECT_EQ(s.job(b).state, JobState::queued);
}

TEST(CoarseFirstStore, RefineNoneWaitsForPromotionByHandWhichPromotesOnce) {
  CoarseFirstStore s(3, rule_of(RefineKind::none));
  std::vector<std::string> ids;
  for (const double value : {0.3, 0.1, 0.4}) ids.push_back(s.run_next(value, 2, Outcome::previewed));
  for (const std::string& id : ids) EXPECT_EQ(s.job(id).state, JobState::previewed);
  EXPECT_FALSE(s.store.claim_next(test::worker("w"), 30));

  RefineRule where = rule_of(RefineKind::where);
  where.conditions = {{"max_displacement", Comparison::less, 0.35}};
  const Promotion promotion = s.store.promote("s", where);
  EXPECT_EQ(promotion.candidates, 3);
  EXPECT_EQ(promotion.promoted, (Ids{ids[0], ids[1]}));
  // Promoted jobs keep their place among the candidates, so the same rule selects the same.
  const Promotion again = s.store.promote("s", where);
  EXPECT_EQ(again.selected, (Ids{ids[0], ids[1]}));
  EXPECT_TRUE(again.promoted.empty());
  EXPECT_THROW(s.store.promote("nope", where), InputError);
}

TEST(CoarseFirstStore, AJobListedByASweepOfEveryLevelLeavesItsPreviewBehind) {
  CoarseFirstStore s(2, rule_of(RefineKind::none));
  const std::string id = s.run_next(0.3, 2, Outcome::previewed);
  s.store.add_sweep("everything", "all.toml", test::thickness_jobs(0, 1));
  const Job job = s.job(id);
  EXPECT_EQ(job.state, JobState::queued);
  EXPECT_FALSE(job.preview_levels);
  EXPECT_EQ(job.levels_to_run(), 3);
}

}  // namespace
}  // namespace psq::db
