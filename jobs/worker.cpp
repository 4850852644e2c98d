#include "jobs/worker.hpp"

#include "jobs/test_hooks.hpp"

namespace psq::jobs {

WorkerSummary run_worker(const std::filesystem::path& database,
                         const std::filesystem::path& runs_dir, const SolverFactory& factory,
                         const WorkerOptions& options, const ExecutorEvents& events,
                         const std::atomic<bool>& stop) {
  db::JobStoreOptions store_options;
  store_options.inside_claim_transaction = [] { test_point("claim_transaction"); };
  store_options.inside_record_transaction = [] { test_point("record_transaction"); };
  db::JobStore store(database, store_options);
  JobExecutor executor(store, database, runs_dir, factory, options.executor, events, stop);
  WorkerSummary summary;
  while (!stop.load()) {
    const std::optional<db::Claim> claim =
        store.claim_next(options.identity, options.lease_seconds, options.selection);
    if (!claim) break;
    test_point("claimed");
    switch (executor.run(*claim)) {
      case RunOutcome::done:
        ++summary.done;
        break;
      case RunOutcome::previewed:
        ++summary.previewed;
        break;
      case RunOutcome::failed:
        ++summary.failed;
        break;
      case RunOutcome::interrupted:
        ++summary.interrupted;
        break;
      case RunOutcome::lease_lost:
        ++summary.lease_lost;
        break;
    }
  }
  return summary;
}

}  // namespace psq::jobs
