#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>
#include <iterator>
#include <string>

#include "db/job_store.hpp"
#include "db/schema.hpp"
#include "store_fixtures.hpp"
#include "support/test_paths.hpp"

namespace psq::db {
namespace {

std::string single_text(SqliteConnection& connection, const std::string& sql) {
  auto query = connection.prepare(sql);
  EXPECT_TRUE(query.step()) << sql;
  return query.text(0);
}

std::int64_t single_integer(SqliteConnection& connection, const std::string& sql) {
  auto query = connection.prepare(sql);
  EXPECT_TRUE(query.step()) << sql;
  return query.integer(0);
}

/// The message of the InputError that `open` throws; fails the test if it throws nothing.
template <class Open>
std::string input_error_of(Open open) {
  try {
    open();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

TEST(JobStoreSchema, FreshStoreIsCreatedWithParentsInWalModeAtTheLatestVersion) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "nested" / ".psq" / "psq.db";
  { JobStore store(path); }
  ASSERT_TRUE(std::filesystem::exists(path));
  SqliteConnection raw(path, 1000);
  EXPECT_EQ(single_text(raw, "PRAGMA journal_mode"), "wal");  // persistent in the file
  EXPECT_EQ(schema_version(raw), latest_schema_version());
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM schema_version"), latest_schema_version());
  for (const char* table : {"sweeps", "jobs", "sweep_jobs", "levels"})
    EXPECT_EQ(single_integer(raw, fmt::format("SELECT COUNT(*) FROM sqlite_schema WHERE "
                                              "type = 'table' AND name = '{}'", table)),
              1)
        << table;
  // The claim query must be served by an index, not a scan of every job.
  auto explain = raw.prepare(
      "EXPLAIN QUERY PLAN SELECT id FROM jobs WHERE state = 'queued' ORDER BY number LIMIT 1");
  std::string details;
  while (explain.step()) details += explain.text(3) + "\n";
  EXPECT_NE(details.find("USING INDEX jobs_by_state"), std::string::npos) << details;
  EXPECT_EQ(details.find("TEMP B-TREE"), std::string::npos) << details;
}

TEST(JobStoreSchema, ReopeningKeepsDataAndAppliesNothingTwice) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  {
    JobStore store(path);
    store.add_sweep("s", "s.toml", test::thickness_jobs(0, 3));
  }
  std::string schema_before;
  {
    SqliteConnection raw(path, 1000);
    schema_before = single_text(raw, "SELECT group_concat(sql, ';') FROM sqlite_schema");
  }
  JobStore reopened(path);
  EXPECT_EQ(reopened.status("s").total(), 3);
  SqliteConnection raw(path, 1000);
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM schema_version"), latest_schema_version());
  EXPECT_EQ(single_text(raw, "SELECT group_concat(sql, ';') FROM sqlite_schema"), schema_before);
}

TEST(JobStoreSchema, NewerSchemaIsRefusedWithUpgradeAdvice) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  { JobStore store(path); }
  const int future = latest_schema_version() + 6;
  {
    SqliteConnection raw(path, 1000);
    raw.prepare("INSERT INTO schema_version (version, description) VALUES (?1, 'future')")
        .bind_all(future)
        .run();
  }
  const std::string message = input_error_of([&] { JobStore store(path); });
  EXPECT_EQ(message, fmt::format("{} has schema version {} but this psq understands up to {}; "
                                 "upgrade psq",
                                 path.string(), future, latest_schema_version()));
}

/// Drops what version 6 added, leaving what a version-5 store holds (its jobs table then
/// lacks only the state 'previewed' in its CHECK, which the upgrade's rebuild restores anyway).
constexpr const char* kVersionSixColumns =
    "ALTER TABLE jobs DROP COLUMN promoted; ALTER TABLE jobs DROP COLUMN preview_levels; "
    "ALTER TABLE levels DROP COLUMN outputs; ALTER TABLE sweeps DROP COLUMN refine; "
    "ALTER TABLE sweeps DROP COLUMN refine_pending; ";

/// Drops what version 9 added (each job's method), leaving what a version-8 store holds.
constexpr const char* kVersionNineColumns = "ALTER TABLE jobs DROP COLUMN method; ";

/// Drops what versions 9 and 8 added (frames and probe readings), leaving what a version-7
/// store holds.
const std::string kVersionEightTables =
    std::string(kVersionNineColumns) + "DROP TABLE frames; DROP TABLE probe_readings; ";

TEST(JobStoreSchema, AVersionEightStoreGainsTheMethodItsJobsDepthsImplied) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  {
    JobStore store(path);
    std::vector<NewJob> jobs = test::thickness_jobs(0, 1, 1);
    jobs.push_back(test::thickness_jobs(1, 1, 3).front());
    store.add_sweep("s", "s.toml", jobs);
  }
  {
    SqliteConnection raw(path, 1000);
    raw.execute(std::string(kVersionNineColumns) + "DELETE FROM schema_version WHERE version > 8");
    ASSERT_EQ(schema_version(raw), 8);
  }
  JobStore upgraded(path);
  const std::vector<JobResult> results = upgraded.results(JobSelection::all());
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].job.depth, 1);
  EXPECT_EQ(results[0].job.method, Method::direct);
  EXPECT_EQ(results[1].job.depth, 3);
  EXPECT_EQ(results[1].job.method, Method::progressive);
  SqliteConnection raw(path, 1000);
  EXPECT_EQ(schema_version(raw), latest_schema_version());
  // A name that is not a method is refused by the table itself.
  EXPECT_THROW(raw.execute("UPDATE jobs SET method = 'fast'"), DatabaseError);
}

/// Drops what versions 8 and 7 added (the hierarchy cache uses), leaving what a version-6 store
/// holds.
const std::string kVersionSevenTables =
    kVersionEightTables + "DROP TABLE hierarchy_cache_uses; ";

TEST(JobStoreSchema, AVersionSevenStoreGainsFramesWithProbeReadingsKeepingItsLevels) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  {
    JobStore store(path);
    store.add_sweep("s", "s.toml", test::thickness_jobs(0, 2));
    const auto claim = store.claim_next(test::worker("w"), 30);
    LevelRecord level;
    level.checkpoint_path = "/runs/snapshot_0.h5";
    level.checkpoint_checksum = "fnv1a64:0000000000000001";
    store.record_level(claim->lease, level);
  }
  {
    SqliteConnection raw(path, 1000);
    raw.execute(kVersionEightTables + "DELETE FROM schema_version WHERE version > 7");
    ASSERT_EQ(schema_version(raw), 7);
    ASSERT_EQ(single_integer(raw, "SELECT COUNT(*) FROM sqlite_schema WHERE name IN ('frames', "
                                  "'probe_readings')"),
              0);
  }
  JobStore upgraded(path);
  const auto claim = upgraded.claim_next(test::worker("w2"), 30);
  ASSERT_TRUE(claim);
  const std::string first = upgraded.results(JobSelection::all()).front().job.id;
  // The level stored before the upgrade is still there, without frames.
  const auto before = upgraded.results(JobSelection::job(first));
  ASSERT_EQ(before.front().levels.size(), 1u);
  EXPECT_TRUE(before.front().levels.front().frames.empty());

  // Two records of one level: the second repeats frame 2 (a settling step recorded again) and
  // adds frame 3; frames come back in order, frame 2 as last written.
  LevelRecord level;
  level.frames = {{1, 0.5, {{"tip", "displacement", {0, 0, -0.25}}}},
                  {2, 0.75, {{"tip", "displacement", {0, 0, -0.5}}}}};
  upgraded.record_level(claim->lease, level);
  level.frames = {{3, 1.0, {{"clamp", "reaction", {0, 0, -4}}, {"tip", "displacement", {0, 0, -1}}}},
                  {2, 0.75, {{"tip", "displacement", {0, 0, -0.625}}}}};
  upgraded.record_level(claim->lease, level);
  const std::vector<FrameReadings> expected{
      {1, 0.5, {{"tip", "displacement", {0, 0, -0.25}}}},
      {2, 0.75, {{"tip", "displacement", {0, 0, -0.625}}}},
      {3, 1.0, {{"clamp", "reaction", {0, 0, -4}}, {"tip", "displacement", {0, 0, -1}}}}};
  const auto results = upgraded.results(JobSelection::job(claim->job.id));
  ASSERT_EQ(results.front().levels.size(), 1u);
  EXPECT_EQ(results.front().levels.front().frames, expected);

  SqliteConnection raw(path, 1000);
  EXPECT_EQ(schema_version(raw), latest_schema_version());
  // An unknown kind is refused by the table itself.
  EXPECT_THROW(raw.execute("INSERT INTO probe_readings VALUES ('" + claim->job.id +
                           "', 0, 1, 'p', 'speed', 0, 0, 0)"),
               DatabaseError);
  // A fenced write: a stale attempt writes no frames.
  Lease stale = claim->lease;
  stale.attempt -= 1;
  EXPECT_THROW(upgraded.record_level(stale, level), LeaseLostError);
}

TEST(JobStoreSchema, AVersionSixStoreGainsHierarchyCacheUsesKeepingItsJobs) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  {
    JobStore store(path);
    store.add_sweep("s", "s.toml", test::thickness_jobs(0, 2));
  }
  {
    SqliteConnection raw(path, 1000);
    raw.execute(kVersionSevenTables + "DELETE FROM schema_version WHERE version > 6");
    ASSERT_EQ(schema_version(raw), 6);
    ASSERT_EQ(single_integer(raw, "SELECT COUNT(*) FROM sqlite_schema WHERE name = "
                                  "'hierarchy_cache_uses'"),
              0);
  }
  JobStore upgraded(path);
  EXPECT_EQ(upgraded.status("s").total(), 2);
  const auto claim = upgraded.claim_next(test::worker("w"), 30);
  ASSERT_TRUE(claim);
  upgraded.record_hierarchy_uses(claim->lease, {{"00000000000000ab", false, 2.5},
                                                {"00000000000000cd", true, 0.125}});
  const std::vector<JobResult> results = upgraded.results(JobSelection::job(claim->job.id));
  ASSERT_EQ(results.front().hierarchy_uses.size(), 2u);
  EXPECT_EQ(results.front().hierarchy_uses[1].key, "00000000000000cd");
  EXPECT_TRUE(results.front().hierarchy_uses[1].hit);
  SqliteConnection raw(path, 1000);
  EXPECT_EQ(schema_version(raw), latest_schema_version());
  // A negative time is refused by the table itself.
  EXPECT_THROW(raw.execute("INSERT INTO hierarchy_cache_uses VALUES ('" + claim->job.id +
                           "', 1, 9, 'k', 0, -1.0)"),
               DatabaseError);
}

TEST(JobStoreSchema, AVersionFiveStoreIsRebuiltKeepingJobsLevelsAndLinks) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  {
    JobStore store(path);
    store.add_sweep("s", "s.toml", test::thickness_jobs(0, 3));
    const auto claim = store.claim_next(test::worker("w"), 30);
    LevelRecord level;
    level.status = LevelStatus::done;
    level.checkpoint_path = "/runs/level_0.h5";
    level.checkpoint_checksum = "fnv1a64:0000000000000001";
    store.record_level(claim->lease, level);
  }
  {
    SqliteConnection raw(path, 1000);
    raw.execute(kVersionSevenTables + kVersionSixColumns +
                "DELETE FROM schema_version WHERE version > 5");
    ASSERT_EQ(schema_version(raw), 5);
  }
  JobStore upgraded(path);
  SqliteConnection raw(path, 1000);
  EXPECT_EQ(schema_version(raw), latest_schema_version());
  // Dropping the old jobs table must not have cascaded into the tables that refer to it.
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM sweep_jobs"), 3);
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM levels"), 1);
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM jobs WHERE state = 'running'"), 1);
  EXPECT_TRUE(upgraded.integrity_problems().empty());
  // The rebuilt table takes the new state.
  raw.execute("UPDATE jobs SET state = 'previewed' WHERE state = 'queued'");
  EXPECT_EQ(upgraded.status("s").counts.at(JobState::previewed), 2);
  EXPECT_EQ(upgraded.results(JobSelection::all()).front().levels.front().checkpoint_path,
            "/runs/level_0.h5");
}

TEST(JobStoreSchema, AVersionThreeStoreIsUpgradedKeepingItsJobs) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  {
    JobStore store(path);
    store.add_sweep("s", "s.toml", test::thickness_jobs(0, 2));
  }
  {
    // Back to what a store written by a version-3 psq holds.
    SqliteConnection raw(path, 1000);
    raw.execute(
        kVersionSevenTables + kVersionSixColumns +
        "ALTER TABLE jobs DROP COLUMN progress_attempt; ALTER TABLE jobs DROP COLUMN stalls; "
        "ALTER TABLE levels DROP COLUMN refinement; DELETE FROM schema_version WHERE version > 3");
    ASSERT_EQ(schema_version(raw), 3);
  }
  JobStore upgraded(path);
  EXPECT_EQ(upgraded.status("s").total(), 2);
  SqliteConnection raw(path, 1000);
  EXPECT_EQ(schema_version(raw), latest_schema_version());
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM pragma_table_info('jobs') WHERE name IN "
                                "('progress_attempt', 'stalls')"),
            2);
  EXPECT_EQ(single_integer(raw, "SELECT SUM(stalls) FROM jobs"), 0);
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM pragma_table_info('levels') WHERE name = "
                                "'refinement'"),
            1);
}

TEST(JobStoreSchema, FileThatIsNotADatabaseIsRefusedByName) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  std::string text;
  for (int i = 0; i < 200; ++i) text += "this is a sweep file, not a database\n";
  psq::test::write_file(path, text);
  const std::string message = input_error_of([&] { JobStore store(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("not a SQLite database"), std::string::npos) << message;
  // Refusing must not have damaged the file.
  std::ifstream in(path);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), text);
}

TEST(JobStoreSchema, SqliteDatabaseOfAnotherProgramIsRefused) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "other.db";
  {
    SqliteConnection raw(path, 1000);
    raw.execute("CREATE TABLE photos (id INTEGER PRIMARY KEY, file TEXT)");
  }
  const std::string message = input_error_of([&] { JobStore store(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("not a psq job store"), std::string::npos) << message;
  SqliteConnection raw(path, 1000);
  EXPECT_EQ(single_integer(raw, "SELECT COUNT(*) FROM sqlite_schema WHERE type = 'table'"), 1);
}

TEST(JobStoreSchema, UncreatableDirectoryIsReportedWithThePath) {
  const auto dir = psq::test::fresh_temp_dir("db-schema");
  psq::test::write_file(dir / "plain-file", "x");
  const auto path = dir / "plain-file" / "sub" / "psq.db";
  const std::string message = input_error_of([&] { JobStore store(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("cannot create the directory"), std::string::npos) << message;
}

TEST(JobStoreSchema, SqlErrorsNameTheStatementAndTheDatabase) {
  const auto path = psq::test::fresh_temp_dir("db-schema") / "psq.db";
  SqliteConnection raw(path, 1000);
  try {
    raw.execute("SELECT no_such_column FROM no_such_table");
    FAIL() << "expected DatabaseError";
  } catch (const DatabaseError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find("no_such_table"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace psq::db
