// Expanded sweeps in the job store: adding twice adds nothing, extending adds only new jobs.

#include <gtest/gtest.h>

#include "db/job_store.hpp"
#include "jobs/sweep_file.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

const std::string kHeader = "name = \"s\"\nscene = \"scene.toml\"\n[grid]\n";

class SweepInStore : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_temp_dir("sweep_store");
    std::filesystem::copy_file(test::source_dir() / "jobs/scenes/cantilever.toml",
                               dir_ / "scene.toml");
  }
  jobs::Sweep sweep(const std::string& grid) {
    return jobs::read_sweep(test::write_file(dir_ / "sweep.toml", kHeader + grid));
  }
  db::SweepAddition add(db::JobStore& store, const jobs::Sweep& s) {
    return store.add_sweep(s.name, s.file.string(), jobs::new_jobs(s));
  }
  std::filesystem::path dir_;
};

TEST_F(SweepInStore, AddingTwiceAddsNothingTheSecondTime) {
  db::JobStore store(dir_ / "psq.db");
  const auto s = sweep("\"time.frames\" = [3, 4]\n\"time.step\" = [0.1, 0.2]\n");
  EXPECT_EQ(add(store, s).added.size(), 4u);
  const auto again = add(store, sweep("\"time.step\" = [0.2, 0.1]\n\"time.frames\" = [4, 3]\n"));
  EXPECT_TRUE(again.added.empty());
  EXPECT_EQ(again.already_present, 4);
  EXPECT_EQ(store.status("s").total(), 4);
  const auto job = store.find_job(s.jobs[0].id);
  ASSERT_TRUE(job);
  EXPECT_EQ(job->parameters, s.jobs[0].parameters);
  EXPECT_EQ(job->scene, (dir_ / "scene.toml").string());
}

TEST_F(SweepInStore, ExtendingAGridAddsOnlyTheNewJobs) {
  db::JobStore store(dir_ / "psq.db");
  add(store, sweep("\"time.frames\" = [3, 4]\n"));
  const auto extended = sweep("\"time.frames\" = [3, 4, 5]\n\"depth\" = [1, 2]\n");
  const auto addition = add(store, extended);
  // Of 3 × 2 jobs, (3, depth 1) and (4, depth 1) were stored already.
  EXPECT_EQ(addition.already_present, 2);
  ASSERT_EQ(addition.added.size(), 4u);
  for (const std::string& id : addition.added) {
    const auto job = store.find_job(id);
    ASSERT_TRUE(job);
    EXPECT_TRUE(job->depth == 2 || job->parameters["overrides"]["time.frames"] == 5);
  }
  EXPECT_EQ(store.status("s").total(), 6);
}

TEST_F(SweepInStore, PreviewWritesNothing) {
  db::JobStore store(dir_ / "psq.db");
  add(store, sweep("\"time.frames\" = [3]\n"));
  const auto s = sweep("\"time.frames\" = [3, 4]\n");
  const auto preview = store.preview_sweep(s.name, jobs::new_jobs(s));
  EXPECT_EQ(preview.added, std::vector<std::string>{s.jobs[1].id});
  EXPECT_EQ(preview.already_present, 1);
  EXPECT_EQ(store.status("s").total(), 1);
}

}  // namespace
}  // namespace psq
