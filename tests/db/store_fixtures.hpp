#pragma once
// Shared pieces of the job store tests: a clock moved by hand, and sweeps of made-up jobs.

#include <fmt/format.h>

#include <string>
#include <vector>

#include "db/job_store.hpp"

namespace psq::db::test {

/// Time that only moves when a test says so.
struct ManualClock {
  double now = 1.7e9;
  JobStoreOptions options() {
    JobStoreOptions options;
    options.clock = [this] { return now; };
    return options;
  }
};

/// Jobs `first` .. `first + count − 1` of a thickness sweep; job i always has the same id and
/// parameters, so overlapping ranges describe the same jobs.
inline std::vector<NewJob> thickness_jobs(int first, int count, int depth = 3,
                                          int max_attempts = 3) {
  std::vector<NewJob> jobs;
  for (int i = first; i < first + count; ++i)
    jobs.push_back({fmt::format("job-{:04}", i),
                    {{"thickness", 1e-3 * (i + 1)}, {"E", 1e6}, {"depth", depth}},
                    "jobs/scenes/sheet.toml",
                    depth,
                    method_of_depth(depth),
                    max_attempts,
                    std::nullopt});
  return jobs;
}

inline WorkerInfo worker(const std::string& id) { return {id, "testhost", "0.1.0-test"}; }

}  // namespace psq::db::test
