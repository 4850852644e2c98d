// `psq slurm submit|sync|task`: a sweep's jobs as a SLURM job array (docs/slurm.md).
//
// submit freezes the sweep's queued jobs into a manifest, submits one array task per job and
// claims each job in the store for its task (a lease owned by "slurm:<array>_<index>"). Each
// task (`psq slurm task`, run by the array script) runs its one job with the same worker loop
// and executor as `psq work`, against a store of its own inside the job's directory, and
// leaves a result file there; it checkpoints and stops on SIGTERM (scancel, scontrol requeue,
// preemption) and on the SIGUSR1 that SLURM sends before the time limit, after which it
// requeues itself. sync reads what the scheduler says and the result files, and brings both
// into the store. The submitting host's store is never opened by a task.

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <set>
#include <thread>

#include "db/job_store.hpp"
#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "runner/commands.hpp"
#include "runner/slurm_files.hpp"
#include "runner/slurm_scheduler.hpp"
#include "runner/slurm_tasks.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

namespace fs = std::filesystem;
using slurm::Manifest;
using slurm::TaskResult;

/// A job claimed for an array task stays claimed while the cluster has it, however long it
/// waits in the queue: the lease outlives any sane queue wait, and `psq slurm sync` (not a
/// heartbeat) ends it.
constexpr double kClusterLeaseSeconds = 365.0 * 24 * 3600;
/// The lease inside a task's own store: short, because a task that SLURM starts again after a
/// kill must wait for its predecessor's lease to run out (SLURM runs one instance at a time).
constexpr double kTaskLeaseSeconds = 3.0;

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string environment(const char* name) {
  const char* value = std::getenv(name);
  return value ? value : "";
}

// ---- submit ------------------------------------------------------------------------------

struct SubmitOptions {
  std::string sweep;
  std::string partition;
  std::string time;
  std::string mem;
  int max_parallel = 0;
  int snapshot_iterations = 50;
  double snapshot_seconds = 60.0;
  int signal_before = 300;
  std::string database;
};

/// A value for an #SBATCH line, which sbatch splits at white space.
const std::string& sbatch_value(const std::string& option, const std::string& value) {
  if (value.find_first_of(" \t\r\n\"'") != std::string::npos)
    throw InputError(
        fmt::format("--{} '{}': spaces and quotes cannot go into an sbatch option", option, value));
  return value;
}

/// A word for the shell, single-quoted.
std::string shell_word(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string array_script(const SubmitOptions& options, const fs::path& submission,
                         const fs::path& manifest, std::size_t tasks) {
  std::string script = fmt::format(
      "#!/bin/bash\n"
      "# Written by psq slurm submit: sweep '{}', {} jobs, one array task each (docs/slurm.md).\n"
      "#SBATCH --job-name=psq-{}\n"
      "#SBATCH --array=0-{}{}\n"
      "#SBATCH --requeue\n"
      "#SBATCH --signal=B:USR1@{}\n"
      "#SBATCH --open-mode=append\n"
      "#SBATCH --output={}\n",
      options.sweep, tasks, sbatch_value("sweep", options.sweep), tasks - 1,
      options.max_parallel > 0 ? fmt::format("%{}", options.max_parallel) : "",
      options.signal_before, sbatch_value("db", (submission / "task-%A_%a.log").string()));
  if (!options.partition.empty())
    script += fmt::format("#SBATCH --partition={}\n", sbatch_value("partition", options.partition));
  if (!options.time.empty())
    script += fmt::format("#SBATCH --time={}\n", sbatch_value("time", options.time));
  if (!options.mem.empty())
    script += fmt::format("#SBATCH --mem={}\n", sbatch_value("mem", options.mem));
  // The batch shell becomes psq, so the scheduler's signals (B:USR1, SIGTERM) reach it.
  script += fmt::format("exec {} slurm task {} \"$SLURM_ARRAY_TASK_ID\"\n",
                        shell_word(fs::canonical("/proc/self/exe").string()),
                        shell_word(manifest.string()));
  return script;
}

std::vector<db::NewJob> queued_jobs(db::JobStore& store, const std::string& sweep) {
  std::vector<db::NewJob> jobs;
  for (const db::JobResult& r : store.results(db::JobSelection::sweep(sweep))) {
    if (r.job.state != db::JobState::queued) continue;
    // An array task runs every level of its job; stopping at a preview is psq work's alone.
    if (r.job.levels_to_run() < r.job.depth)
      throw InputError(fmt::format(
          "job {} of sweep '{}' is to stop at its preview (a coarse-first sweep), which SLURM "
          "array tasks cannot do yet: run the previews with psq work, then submit the promoted "
          "jobs",
          r.job.id, sweep));
    jobs.push_back({r.job.id, r.job.parameters, r.job.scene, r.job.depth, r.job.method,
                    static_cast<int>(r.job.max_attempts), std::nullopt});
  }
  return jobs;
}

/// Claims every submitted job for its array task. A job that a local `psq work` claimed since
/// the manifest was written keeps that claim, and its task is cancelled.
std::vector<slurm::SlurmTask> claim_for_tasks(db::JobStore& store, slurm::Scheduler& scheduler,
                                              const Manifest& manifest, const fs::path& file,
                                              const std::string& array_id) {
  std::vector<slurm::SlurmTask> tasks;
  for (std::size_t i = 0; i < manifest.jobs.size(); ++i) {
    const int index = static_cast<int>(i);
    const db::WorkerInfo owner{slurm::slurm_owner(array_id, index),
                               fmt::format("slurm array {}", array_id), PSQ_VERSION};
    const std::optional<db::Claim> claim =
        store.claim_next(owner, kClusterLeaseSeconds, db::JobSelection::job(manifest.jobs[i].id));
    if (!claim) {
      scheduler.cancel(slurm::task_name(array_id, index));
      std::cerr << fmt::format(
          "psq slurm submit: job {} was claimed meanwhile; task {} cancelled\n",
          manifest.jobs[i].id, slurm::task_name(array_id, index));
      continue;
    }
    tasks.push_back({claim->job.id, claim->lease.attempt, array_id, index, file.string(), "PENDING",
                     "", unix_now(), std::nullopt});
  }
  return tasks;
}

int run_submit(const SubmitOptions& options) {
  const fs::path database = database_path(options.database);
  require_database(database);
  db::JobStore store(database);
  store.status(options.sweep);  // an unknown sweep stops here, with the store's message
  Manifest manifest{options.sweep, runs_directory(database), options.snapshot_iterations,
                    options.snapshot_seconds, queued_jobs(store, options.sweep)};
  if (manifest.jobs.empty()) {
    std::cout << fmt::format("sweep '{}': no queued jobs to submit\n", options.sweep);
    return 0;
  }
  const fs::path submission =
      fs::absolute(database).parent_path() / "slurm" /
      fmt::format("{}-{}-{}", options.sweep, static_cast<long long>(unix_now()), ::getpid());
  const fs::path manifest_file = submission / "manifest.json";
  const fs::path script_file = submission / "array.sbatch";
  slurm::Scheduler scheduler;
  std::string array_id;
  try {
    std::error_code error;
    fs::create_directories(submission, error);
    if (error)
      throw InputError(
          fmt::format("cannot create the submission directory {}: {}; make the "
                      "store's directory writable",
                      submission.string(), error.message()));
    slurm::write_manifest(manifest_file, manifest);
    const std::string script =
        array_script(options, submission, manifest_file, manifest.jobs.size());
    write_file_atomically(script_file, [&](std::ostream& out) { out << script; });
    array_id = scheduler.submit(script_file);
  } catch (...) {
    // Nothing was submitted: leave no trace of the attempt.
    std::error_code ignored;
    fs::remove_all(submission, ignored);
    throw;
  }
  const std::vector<slurm::SlurmTask> tasks =
      claim_for_tasks(store, scheduler, manifest, manifest_file, array_id);
  slurm::SlurmTaskTable(database).record(tasks);
  std::cout << fmt::format(
      "sweep '{}': {} jobs submitted as SLURM array job {} ({}); psq slurm sync {} brings "
      "their results in\n",
      options.sweep, tasks.size(), array_id, script_file.string(), options.sweep);
  return 0;
}

// ---- sync --------------------------------------------------------------------------------

struct SyncOptions {
  std::string sweep;
  std::string database;
};

/// A job the store holds for an array task.
struct HeldJob {
  db::Job job;
  std::string array_id;
  int index = 0;
  db::Lease lease() const { return {job.id, job.attempt, kClusterLeaseSeconds}; }
  std::string task() const { return slurm::task_name(array_id, index); }
};

std::vector<HeldJob> held_jobs(db::JobStore& store, const db::JobSelection& selection) {
  std::vector<HeldJob> held;
  for (db::JobResult& r : store.results(selection))
    if (r.job.state == db::JobState::running)
      if (const auto task = slurm::parse_slurm_owner(r.job.lease_owner))
        held.push_back({std::move(r.job), task->first, task->second});
  return held;
}

/// Where the task's log is: beside its manifest, named as the array script names it.
std::string task_log(const fs::path& manifest, const HeldJob& held) {
  return (manifest.parent_path() / fmt::format("task-{}.log", held.task())).string();
}

/// Whether the job's directory holds a checkpoint written since `since` (Unix seconds).
bool checkpointed_since(const fs::path& run, double since) {
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(run, error)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("level_") || entry.path().extension() != ".h5") continue;
    const auto written = std::chrono::file_clock::to_sys(entry.last_write_time(error));
    if (!error && std::chrono::duration<double>(written.time_since_epoch()).count() >= since)
      return true;
  }
  return false;
}

/// What one sync did, for its summary line.
struct SyncCounts {
  std::map<std::string, int> on_cluster;  ///< by SLURM state
  int done = 0;
  int failed = 0;
  int requeued = 0;             ///< back in the store's queue
  int requeued_on_cluster = 0;  ///< killed tasks that sync requeued in SLURM
};

/// `scontrol requeue` of an ended task; false (the job then goes back to the store's queue)
/// when SLURM refuses, e.g. once the task has left the controller's memory (MinJobAge).
bool requeue_task(slurm::Scheduler& scheduler, const std::string& task) {
  try {
    scheduler.requeue(task);
    return true;
  } catch (const InputError& refused) {
    std::cerr << fmt::format("psq slurm sync: {}; the job goes back to the store's queue\n",
                             refused.what());
    return false;
  }
}

/// Brings one held job's outcome into the store; returns the task row to record.
slurm::SlurmTask sync_job(db::JobStore& store, slurm::Scheduler& scheduler, const fs::path& runs,
                          const HeldJob& held,
                          const std::optional<slurm::TaskState>& seen,
                          const std::optional<slurm::SlurmTask>& known, SyncCounts& counts) {
  const fs::path manifest = known ? known->manifest : "";
  // A row lost to a crash between claim and record (submit) is rebuilt from the lease owner.
  slurm::SlurmTask row{held.job.id,
                       held.job.attempt,
                       held.array_id,
                       held.index,
                       manifest.string(),
                       seen ? seen->state : "UNKNOWN",
                       seen ? seen->reason : "",
                       known ? known->submitted_at : unix_now(),
                       unix_now()};
  std::optional<TaskResult> result = slurm::read_task_result(slurm::task_result(runs, held.job.id));
  // A result file of an earlier submission of the job says nothing about this one.
  if (result && (result->array_id != held.array_id || result->index != held.index)) result.reset();
  const auto say = [&](const std::string& what) {
    std::cout << fmt::format("job {} (task {}): {}\n", held.job.id, held.task(), what);
  };
  if (result && result->state != db::JobState::queued) {
    for (const db::LevelRecord& level : result->levels) store.record_level(held.lease(), level);
    if (result->state == db::JobState::done) {
      store.finish(held.lease(), db::Outcome::done);
      ++counts.done;
      say("done");
    } else {
      // The task has spent the job's attempts already, or the failure is one retrying cannot fix.
      store.finish(held.lease(), db::Outcome::failed_permanently, result->error);
      ++counts.failed;
      say("failed: " + result->error);
    }
    return row;
  }
  if (seen && slurm::is_live(seen->state)) {
    ++counts.on_cluster[seen->state];
    return row;
  }
  const std::string scheduler_word =
      seen ? fmt::format("{}{}", seen->state, seen->reason.empty() ? "" : ", " + seen->reason)
           : "no longer known to the scheduler";
  if (result) {
    // Stopped by a signal after a checkpoint, and SLURM will not run it again (cancelled).
    store.release(held.lease());
    row.reason = "stopped after a checkpoint";
    ++counts.requeued;
    say(
        fmt::format("stopped by the scheduler ({}) after writing a checkpoint; queued again, "
                    "psq slurm submit continues it from there",
                    scheduler_word));
    return row;
  }
  const std::string message = fmt::format(
      "SLURM array task {} ended ({}) without a result: it was killed before it could "
      "checkpoint (scancel --signal=KILL, out of memory, node failure) or failed to start; "
      "its log is {}",
      held.task(), scheduler_word, task_log(manifest, held));
  // An attempt that made progress does not count against the retry bound (DESIGN.md §9): a
  // job that advances through kills always finishes.
  if (checkpointed_since(runs / held.job.id, row.submitted_at)) {
    // SLURM requeues a finished batch job too: the same task, still holding the job's claim,
    // runs again from its checkpoint without a new submission. The window for progress
    // starts anew, so a task killed again and again without advancing ends up below.
    if (seen && requeue_task(scheduler, held.task())) {
      row.state = "REQUEUED";
      row.reason = "killed after progress; requeued by sync";
      row.submitted_at = unix_now();
      ++counts.requeued_on_cluster;
      say(message + "; it made progress: requeued on the cluster, it continues from its "
                    "last checkpoint");
      return row;
    }
    store.release(held.lease());
    row.reason = "killed after progress";
    ++counts.requeued;
    say(message + "; psq slurm submit runs it again from its last checkpoint (it made "
                  "progress: no failure counted)");
    return row;
  }
  store.finish(held.lease(), db::Outcome::failed,
               message + "; psq slurm submit runs it again from its last checkpoint");
  const std::optional<db::Job> now = store.find_job(held.job.id);
  if (now && now->state == db::JobState::queued)
    ++counts.requeued;
  else
    ++counts.failed;
  say(message);
  return row;
}

/// `psq cancel` ends a job's claim in the store; the cluster learns it here: its task, if
/// still live, is cancelled (it checkpoints on the SIGTERM, so psq retry can continue it).
void cancel_tasks_of_cancelled_jobs(slurm::Scheduler& scheduler, slurm::SlurmTaskTable& table,
                                    const std::string& sweep,
                                    const std::map<std::string, slurm::TaskState>& states,
                                    std::vector<slurm::SlurmTask>& rows) {
  for (slurm::SlurmTask& task : table.cancelled(sweep)) {
    const std::string name = slurm::task_name(task.array_id, task.index);
    const auto seen = states.find(name);
    if (seen == states.end() || !slurm::is_live(seen->second.state)) continue;
    scheduler.cancel(name);
    std::cout << fmt::format("job {} (task {}): cancelled in the store; task cancelled\n",
                             task.job_id, name);
    task.state = "CANCELLED";
    task.reason = "psq cancel";
    task.synced_at = unix_now();
    rows.push_back(std::move(task));
  }
}

int run_sync(const SyncOptions& options) {
  const fs::path database = database_path(options.database);
  require_database(database);
  db::JobStore store(database);
  const db::JobSelection selection =
      options.sweep.empty() ? db::JobSelection::all() : db::JobSelection::sweep(options.sweep);
  if (!options.sweep.empty()) store.status(options.sweep);  // unknown sweep: its message
  slurm::SlurmTaskTable table(database);
  const std::vector<HeldJob> held = held_jobs(store, selection);
  std::set<std::string> arrays;
  for (const HeldJob& h : held) arrays.insert(h.array_id);
  for (const slurm::SlurmTask& t : table.cancelled(options.sweep))
    if (slurm::is_live(t.state)) arrays.insert(t.array_id);
  // The scheduler first, the result files second: a task writes its result before it ends,
  // so a task seen ended without a result file has none.
  slurm::Scheduler scheduler;
  const std::map<std::string, slurm::TaskState> states =
      scheduler.states({arrays.begin(), arrays.end()});
  std::map<std::pair<std::string, std::int64_t>, slurm::SlurmTask> known;
  for (slurm::SlurmTask& t : table.holding(options.sweep))
    known.emplace(std::pair{t.job_id, t.attempt}, std::move(t));
  SyncCounts counts;
  std::vector<slurm::SlurmTask> rows;
  for (const HeldJob& h : held) {
    const auto seen = states.find(h.task());
    const auto row = known.find({h.job.id, h.job.attempt});
    rows.push_back(sync_job(store, scheduler, runs_directory(database), h,
                            seen == states.end() ? std::nullopt : std::optional(seen->second),
                            row == known.end() ? std::nullopt : std::optional(row->second),
                            counts));
  }
  cancel_tasks_of_cancelled_jobs(scheduler, table, options.sweep, states, rows);
  table.record(rows);
  std::string cluster;
  for (const auto& [state, n] : counts.on_cluster) cluster += fmt::format(", {} {}", n, state);
  std::cout << fmt::format("psq slurm sync: {} done, {} failed, {} queued again, {} requeued on "
                           "the cluster{}\n",
                           counts.done, counts.failed, counts.requeued, counts.requeued_on_cluster,
                           cluster.empty() ? ", none left on the cluster" : cluster);
  return 0;
}

// ---- task --------------------------------------------------------------------------------

struct TaskOptions {
  std::string manifest;
  int index = 0;
};

/// Makes the task's own store hold the job, ready to be claimed: added once; run again when
/// the store that submitted it decided so (a failed or cancelled run here is retried); and a
/// run that SLURM killed (its lease still running here) requeued once its lease has run out.
void prepare_task_store(const fs::path& file, const Manifest& manifest, const fs::path& source,
                        const db::NewJob& job) {
  db::JobStore store(file);
  store.add_sweep(manifest.sweep, source.string(), {job});
  const db::JobSelection selection = db::JobSelection::job(job.id);
  store.retry(selection, true);
  if (const std::optional<db::Job> stored = store.find_job(job.id);
      stored && stored->state == db::JobState::running && stored->lease_expiry) {
    const double wait = *stored->lease_expiry - unix_now() + 0.1;
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    store.requeue_interrupted(selection);
  }
}

TaskResult task_outcome(const fs::path& file, const std::string& job_id, int index) {
  db::JobStore store(file);
  db::JobResult r = store.results(db::JobSelection::job(job_id)).front();
  TaskResult result{environment("SLURM_ARRAY_JOB_ID"), index, db::JobState::queued, r.job.error,
                    std::move(r.levels)};
  if (r.job.state == db::JobState::done) result.state = db::JobState::done;
  if (r.job.state == db::JobState::failed || r.job.state == db::JobState::cancelled)
    result.state = db::JobState::failed;
  return result;
}

int run_task(const TaskOptions& options) {
  const fs::path manifest_file = fs::absolute(options.manifest);
  const Manifest manifest = slurm::read_manifest(manifest_file);
  if (options.index < 0 || options.index >= static_cast<int>(manifest.jobs.size()))
    throw InputError(fmt::format("{}: no task {} (the manifest has {} jobs)",
                                 manifest_file.string(), options.index, manifest.jobs.size()));
  const db::NewJob& job = manifest.jobs[options.index];
  // SIGUSR1 is SLURM's warning before the time limit (--signal=B:USR1@S in the script).
  install_stop_handlers({SIGINT, SIGTERM, SIGUSR1});
  const fs::path store_file = slurm::task_store(manifest.runs, job.id);
  prepare_task_store(store_file, manifest, manifest_file, job);
  WorkSettings settings;
  settings.database = store_file.string();
  settings.workers = 1;
  settings.lease_seconds = kTaskLeaseSeconds;
  settings.snapshot_iterations = manifest.snapshot_iterations;
  settings.snapshot_seconds = manifest.snapshot_seconds;
  const int code = work_in_this_process(
      settings,
      {store_file, manifest.runs, slurm::task_directory(manifest.runs, job.id) / "cache"});
  slurm::write_task_result(slurm::task_result(manifest.runs, job.id),
                           task_outcome(store_file, job.id, options.index));
  const std::string slurm_job = environment("SLURM_JOB_ID");
  if (stop_signal() == SIGUSR1 && !slurm_job.empty()) {
    // The time limit is near: the checkpoint is written; run again later from it. The requeue
    // sends this task SIGTERM, which (a second signal) ends it at once.
    std::cerr << fmt::format("psq slurm task: time limit near; requeueing job {}\n", slurm_job);
    slurm::Scheduler().requeue(slurm_job);
  }
  return code;
}

}  // namespace

void register_slurm_command(CLI::App& app, std::vector<Command>& commands) {
  CLI::App* slurm = app.add_subcommand("slurm", "Run a sweep's jobs as a SLURM job array");
  slurm->require_subcommand(1);

  auto submit = std::make_shared<SubmitOptions>();
  CLI::App* s = slurm->add_subcommand(
      "submit", "Submit the sweep's queued jobs as a job array (one task per job)");
  s->add_option("sweep", submit->sweep, "Sweep name")->required();
  s->add_option("--partition", submit->partition, "SLURM partition (default: the cluster's)");
  s->add_option("--max-parallel", submit->max_parallel,
                "At most this many tasks run at once (the array's %K throttle)")
      ->check(CLI::PositiveNumber);
  s->add_option("--time", submit->time, "Time limit per task, in sbatch's format (e.g. 2:00:00)");
  s->add_option("--mem", submit->mem, "Memory per task, in sbatch's format (e.g. 4G)");
  s->add_option("--signal-before", submit->signal_before,
                "Seconds before the time limit at which a task checkpoints and requeues itself")
      ->check(CLI::PositiveNumber);
  s->add_option("--snapshot-iterations", submit->snapshot_iterations,
                "Write an in-level snapshot after this many Newton iterations")
      ->check(CLI::PositiveNumber);
  s->add_option("--snapshot-seconds", submit->snapshot_seconds,
                "...or after this many seconds since the last checkpoint")
      ->check(CLI::PositiveNumber);
  add_database_option(*s, submit->database);
  commands.push_back({s, [submit] { return run_submit(*submit); }});

  auto sync = std::make_shared<SyncOptions>();
  CLI::App* y = slurm->add_subcommand(
      "sync", "Bring the array tasks' results and the scheduler's state into the store");
  y->add_option("sweep", sync->sweep, "Only this sweep (default: every sweep)");
  add_database_option(*y, sync->database);
  commands.push_back({y, [sync] { return run_sync(*sync); }});

  auto task = std::make_shared<TaskOptions>();
  CLI::App* t = slurm->add_subcommand("task", "Run one array task (the array script calls it)");
  t->group("");  // internal
  t->add_option("manifest", task->manifest, "The submission's manifest.json")->required();
  t->add_option("index", task->index, "The array task index")->required();
  commands.push_back({t, [task] { return run_task(*task); }});
}

}  // namespace psq::runner
