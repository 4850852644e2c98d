// A store that runs out of space (simulated by a file size limit) refuses the write with a
// clear message and stays as it was.

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "child_process.hpp"
#include "db/job_store.hpp"
#include "store_fixtures.hpp"
#include "support/test_paths.hpp"

namespace psq::db {
namespace {

using test::ChildProcess;
using test::exited_cleanly;
using test::thickness_jobs;

TEST(JobStoreDiskFull, WriteBeyondTheFileSizeLimitIsRefusedAndRolledBack) {
  const auto dir = psq::test::fresh_temp_dir("db-disk-full");
  const auto path = dir / "psq.db";
  { JobStore(path).add_sweep("small", "small.toml", thickness_jobs(0, 3)); }
  auto big = thickness_jobs(100, 3000);
  for (auto& job : big) job.parameters["note"] = std::string(1000, 'x');  // ~3 MB in all
  const auto message_file = dir / "message.txt";

  ChildProcess child([&] {
    JobStore store(path);
    // Writes past the limit now fail with EFBIG instead of killing the process.
    ::signal(SIGXFSZ, SIG_IGN);
    const auto limit = static_cast<rlim_t>(std::filesystem::file_size(path) + 256 * 1024);
    const rlimit file_size{limit, limit};
    if (::setrlimit(RLIMIT_FSIZE, &file_size) != 0) throw std::runtime_error("setrlimit");
    try {
      store.add_sweep("big", "big.toml", big);
    } catch (const InputError& e) {
      std::ofstream(message_file) << e.what();
      return;
    }
    throw std::runtime_error("a 3 MB transaction got past a 256 kB file size limit");
  });
  ASSERT_TRUE(exited_cleanly(child.wait()));

  std::ifstream in(message_file);
  const std::string message{std::istreambuf_iterator<char>(in), {}};
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_TRUE(message.find("disk full") != std::string::npos ||
              message.find("input/output error") != std::string::npos)
      << message;

  JobStore store(path);
  EXPECT_TRUE(store.integrity_problems().empty());
  const auto sweeps = store.status();
  ASSERT_EQ(sweeps.size(), 1u);  // "big" was rolled back entirely
  EXPECT_EQ(sweeps[0].name, "small");
  EXPECT_EQ(sweeps[0].total(), 3);
  EXPECT_EQ(store.add_sweep("big", "big.toml", thickness_jobs(100, 10)).added.size(), 10u);
}

}  // namespace
}  // namespace psq::db
