#pragma once
// Keeps a claimed job's lease alive from a thread of its own while the worker solves.

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <thread>

#include "db/job_records.hpp"

namespace psq::jobs {

/// Heartbeats `lease` every lease.seconds / 3 on its own connection to the store at
/// `database`, from construction until destruction. lost() turns true once a heartbeat is
/// refused (the job was cancelled, or reclaimed after the lease expired): the worker must stop
/// the job. A heartbeat that fails for another reason (store busy beyond the timeout) is
/// retried at the next beat; the lease only expires if that keeps failing.
class Heartbeat {
 public:
  Heartbeat(const std::filesystem::path& database, db::Lease lease);
  Heartbeat(const Heartbeat&) = delete;
  Heartbeat& operator=(const Heartbeat&) = delete;
  ~Heartbeat();

  [[nodiscard]] bool lost() const { return lost_.load(); }

 private:
  void beat(const std::filesystem::path& database);

  db::Lease lease_;
  std::atomic<bool> lost_{false};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace psq::jobs
