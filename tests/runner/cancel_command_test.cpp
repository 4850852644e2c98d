// `psq cancel SWEEP|JOB`.

#include <gtest/gtest.h>

#include "db/job_store.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

struct Store {
  fs::path dir = test::fresh_temp_dir("cancel_command");
  fs::path db = dir / "psq.db";
  Store() {
    fs::copy_file(test::source_dir() / "jobs/scenes/cantilever.toml", dir / "scene.toml");
    test::write_file(dir / "sweep.toml",
                     "name = \"c\"\nscene = \"scene.toml\"\n[grid]\n"
                     "\"time.frames\" = [2, 3, 4]\n");
    EXPECT_EQ(psq({"sweep", "add", (dir / "sweep.toml").string()}).exit_code, 0);
  }
  test::ProcessResult psq(std::vector<std::string> arguments) const {
    arguments.insert(arguments.end(), {"--db", db.string()});
    return test::run_psq(arguments);
  }
  std::vector<db::JobResult> jobs() const {
    return db::JobStore(db).results(db::JobSelection::all());
  }
};

TEST(CancelCommand, CancelsOneJobByIdThenTheRestOfTheSweep) {
  const Store store;
  const std::string first = store.jobs().front().job.id;
  const auto one = store.psq({"cancel", first});
  EXPECT_EQ(one.exit_code, 0) << one.errors;
  EXPECT_NE(one.output.find("cancelled 1 job "), std::string::npos) << one.output;
  EXPECT_EQ(store.jobs()[0].job.state, db::JobState::cancelled);
  EXPECT_EQ(store.jobs()[1].job.state, db::JobState::queued);
  const auto rest = store.psq({"cancel", "c"});
  EXPECT_NE(rest.output.find("cancelled 2 jobs"), std::string::npos) << rest.output;
  // Nothing is left for a worker.
  const auto work = store.psq({"work", "--workers", "1"});
  EXPECT_EQ(work.exit_code, 0);
  for (const db::JobResult& r : store.jobs()) {
    EXPECT_EQ(r.job.state, db::JobState::cancelled);
    EXPECT_TRUE(r.levels.empty());
  }
}

TEST(CancelCommand, UnknownTargetsAreErrors) {
  const Store store;
  const auto unknown = store.psq({"cancel", "nothing-like-this"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.errors.find("'nothing-like-this' is neither a sweep nor a job id"),
            std::string::npos)
      << unknown.errors;
  EXPECT_EQ(test::run_psq({"cancel", "--help"}).exit_code, 0);
  EXPECT_NE(test::run_psq({"cancel"}).exit_code, 0);  // the target is required
}

}  // namespace
}  // namespace psq
