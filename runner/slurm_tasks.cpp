#include "runner/slurm_tasks.hpp"

#include <fmt/format.h>

#include <charconv>

namespace psq::runner::slurm {

namespace {
constexpr std::string_view kOwnerPrefix = "slurm:";
}  // namespace

std::string slurm_owner(const std::string& array_id, int index) {
  return fmt::format("{}{}_{}", kOwnerPrefix, array_id, index);
}

std::optional<std::pair<std::string, int>> parse_slurm_owner(const std::string& owner) {
  if (!owner.starts_with(kOwnerPrefix)) return std::nullopt;
  const std::string task = owner.substr(kOwnerPrefix.size());
  const auto underscore = task.rfind('_');
  if (underscore == std::string::npos) return std::nullopt;
  int index = 0;
  const char* last = task.data() + task.size();
  const auto [end, error] = std::from_chars(task.data() + underscore + 1, last, index);
  if (error != std::errc() || end != last) return std::nullopt;
  return std::pair{task.substr(0, underscore), index};
}

SlurmTaskTable::SlurmTaskTable(const std::filesystem::path& database)
    : connection_(database, 10'000) {
  connection_.execute("PRAGMA foreign_keys = ON");
}

void SlurmTaskTable::record(const std::vector<SlurmTask>& tasks) {
  db::Transaction write(connection_, db::Transaction::Mode::immediate);
  auto upsert = connection_.prepare(
      "INSERT INTO slurm_tasks (job_id, attempt, array_id, task_index, manifest, state, reason, "
      "submitted_at, synced_at) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?) "
      "ON CONFLICT (job_id, attempt) DO UPDATE SET state = excluded.state, "
      "reason = excluded.reason, submitted_at = excluded.submitted_at, "
      "synced_at = excluded.synced_at");
  for (const SlurmTask& t : tasks)
    upsert.reset()
        .bind_all(t.job_id, t.attempt, t.array_id, t.index, t.manifest, t.state, t.reason,
                  t.submitted_at, t.synced_at)
        .run();
  write.commit();
}

std::vector<SlurmTask> SlurmTaskTable::holding(const std::string& sweep) {
  return select("running", sweep);
}

std::vector<SlurmTask> SlurmTaskTable::cancelled(const std::string& sweep) {
  return select("cancelled", sweep);
}

std::vector<SlurmTask> SlurmTaskTable::select(const std::string& job_state,
                                              const std::string& sweep) {
  // Cancelling leaves the attempt as it was, so a cancelled job's last claim is still known.
  auto query = connection_.prepare(
      "SELECT t.job_id, t.attempt, t.array_id, t.task_index, t.manifest, t.state, t.reason, "
      "t.submitted_at, t.synced_at FROM slurm_tasks t JOIN jobs j ON j.id = t.job_id "
      "WHERE j.state = ?2 AND j.attempt = t.attempt AND (?1 = '' OR EXISTS ("
      "SELECT 1 FROM sweep_jobs sj JOIN sweeps s ON s.id = sj.sweep_id "
      "WHERE sj.job_id = t.job_id AND s.name = ?1)) "
      "ORDER BY CAST(t.array_id AS INTEGER), t.task_index");
  query.bind_all(sweep, job_state);
  std::vector<SlurmTask> tasks;
  while (query.step())
    tasks.push_back({query.text(0), query.integer(1), query.text(2),
                     static_cast<int>(query.integer(3)), query.text(4), query.text(5),
                     query.text(6), query.real(7), query.optional_real(8)});
  return tasks;
}

}  // namespace psq::runner::slurm
