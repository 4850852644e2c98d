#include "jobs/heartbeat.hpp"

#include <chrono>

#include "db/job_store.hpp"
#include "jobs/test_hooks.hpp"

namespace psq::jobs {

Heartbeat::Heartbeat(const std::filesystem::path& database, db::Lease lease)
    : lease_(std::move(lease)), thread_([this, database] { beat(database); }) {}

Heartbeat::~Heartbeat() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void Heartbeat::beat(const std::filesystem::path& database) {
  const auto period = std::chrono::duration<double>(lease_.seconds / 3.0);
  std::unique_ptr<db::JobStore> store;
  std::unique_lock lock(mutex_);
  while (!wake_.wait_for(lock, period, [this] { return stopping_; })) {
    try {
      if (!store) store = std::make_unique<db::JobStore>(database);
      test_point("heartbeat");
      if (!store->heartbeat(lease_)) {
        lost_ = true;
        return;
      }
    } catch (const std::exception&) {
      store.reset();  // reconnect at the next beat
    }
  }
}

}  // namespace psq::jobs
