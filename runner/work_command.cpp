// `psq work [--workers N]`: runs queued jobs until the queue is empty. With one worker the job
// runs in this process; with more, this process supervises N worker processes (psq itself,
// re-executed with --worker-number) and draws their progress. SIGINT/SIGTERM: every worker
// finishes its Newton iteration, writes a snapshot, releases its job and exits with 128 +
// signal; a second signal exits at once.

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <thread>

#include "jobs/direct_level_solver.hpp"
#include "jobs/progress_display.hpp"
#include "jobs/worker.hpp"
#include "jobs/worker_pool.hpp"
#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

/// A job failed in this run (docs/runner.md lists the exit codes).
constexpr int kExitJobsFailed = 5;

std::atomic<bool> stop_requested{false};
std::atomic<int> signals_received{0};
std::atomic<int> last_signal{0};

extern "C" void on_stop_signal(int signal) {
  if (signals_received.fetch_add(1) > 0) ::_exit(128 + signal);  // the second one: at once
  last_signal = signal;
  stop_requested = true;
}

std::string host_name() {
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  return name;
}

int worker_count(const WorkSettings& settings) {
  if (settings.workers > 0) return settings.workers;
  return std::max(1u, std::thread::hardware_concurrency());
}

/// The exit code once no stop was requested, or 128 + the signal.
int exit_code(bool any_failed) {
  if (stop_requested) return 128 + last_signal.load();
  return any_failed ? kExitJobsFailed : 0;
}

}  // namespace

void install_stop_handlers(std::initializer_list<int> signals) {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  for (int signal : signals) ::sigaction(signal, &action, nullptr);
}

int stop_signal() { return stop_requested ? last_signal.load() : 0; }

int work_in_this_process(const WorkSettings& settings, const WorkerPlacement& placement) {
  const bool supervised = settings.worker_number > 0;
  // A supervised worker's stderr is a pipe to its supervisor, which draws the status line.
  jobs::ProgressDisplay display(stderr, !supervised && ::isatty(STDERR_FILENO));
  jobs::ExecutorEvents events;
  events.log = [&](const std::string& line) { display.log(line); };
  events.progress = [&](const jobs::JobProgress& progress) {
    if (supervised)
      std::fprintf(stderr, "%c%s\n", jobs::kProgressMarker,
                   jobs::describe_progress(progress).c_str());
    else
      display.status(0, jobs::describe_progress(progress));
  };
  jobs::WorkerOptions options;
  const std::string host = host_name();
  options.identity = {fmt::format("{}:{}", host, ::getpid()), host, PSQ_VERSION};
  options.lease_seconds = settings.lease_seconds;
  if (!settings.sweep.empty()) options.selection = db::JobSelection::sweep(settings.sweep);
  options.executor = {settings.snapshot_iterations, settings.snapshot_seconds, PSQ_VERSION};
  const auto make_solver = [cache = placement.cache](const Scene& scene, db::Method method,
                                                     int depth) {
    return jobs::make_level_solver(scene, method, depth, cache);
  };
  const jobs::WorkerSummary summary = jobs::run_worker(
      placement.database, placement.runs, make_solver, options, events, stop_requested);
  display.clear();
  if (!supervised)
    display.log(fmt::format("psq work: {} done, {}{} failed{}{}", summary.done,
                            summary.previewed
                                ? fmt::format("{} previewed (waiting for promotion), ",
                                              summary.previewed)
                                : "",
                            summary.failed,
                            summary.interrupted ? ", 1 interrupted and released" : "",
                            summary.lease_lost ? ", some stopped on a lost lease" : ""));
  return exit_code(summary.failed > 0);
}

namespace {

/// Supervises `count` worker processes.
int work_in_processes(const WorkSettings& settings, const std::filesystem::path& database,
                      int count) {
  std::vector<std::vector<std::string>> arguments;
  for (int k = 1; k <= count; ++k) {
    std::vector<std::string> args{"work",
                                  "--db",
                                  std::filesystem::absolute(database).string(),
                                  "--workers",
                                  "1",
                                  "--lease",
                                  fmt::format("{}", settings.lease_seconds),
                                  "--snapshot-iterations",
                                  fmt::format("{}", settings.snapshot_iterations),
                                  "--snapshot-seconds",
                                  fmt::format("{}", settings.snapshot_seconds),
                                  "--worker-number",
                                  fmt::format("{}", k)};
    if (!settings.sweep.empty()) args.insert(args.end(), {"--sweep", settings.sweep});
    arguments.push_back(std::move(args));
  }
  jobs::ProgressDisplay display(stderr, ::isatty(STDERR_FILENO));
  display.log(fmt::format("psq work: {} worker processes on {}", count, database.string()));
  const std::vector<int> codes = jobs::run_worker_processes("/proc/self/exe", arguments, display,
                                                            signals_received, last_signal);
  display.clear();
  bool any_failed = false;
  for (std::size_t k = 0; k < codes.size(); ++k)
    if (codes[k] != 0) {
      any_failed = true;
      display.log(fmt::format("psq work: worker {} exited with code {}", k + 1, codes[k]));
    }
  return exit_code(any_failed);
}

}  // namespace

int run_work(const WorkSettings& settings) {
  const std::filesystem::path database = database_path(settings.database);
  require_database(database);
  install_stop_handlers({SIGINT, SIGTERM});
  const int count = settings.worker_number > 0 ? 1 : worker_count(settings);
  if (count > 1) return work_in_processes(settings, database, count);
  return work_in_this_process(
      settings, {database, runs_directory(database), hierarchy_cache_directory(database)});
}

void register_work_command(CLI::App& app, std::vector<Command>& commands) {
  auto settings = std::make_shared<WorkSettings>();
  CLI::App* command = app.add_subcommand(
      "work", "Run queued jobs (level by level, checkpointed) until the queue is empty");
  add_work_options(*command, *settings);
  command->add_option("--sweep", settings->sweep, "Only this sweep's jobs");
  commands.push_back({command, [settings] { return run_work(*settings); }});
}

}  // namespace psq::runner
