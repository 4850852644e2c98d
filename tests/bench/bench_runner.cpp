// The runner's own overhead per job level: time spent in the job store and writing checkpoints
// against the time spent solving, for one job run through the executor exactly as `psq work`
// runs it (heartbeat thread, in-level snapshots, level checkpoint, XDMF sidecar).
//
//   bench_runner [--edge-length M] [--frames N] [--snapshot-seconds S]   (0.0014, 12, 60)
//
// A square plate clamped along one edge and loaded along the opposite one; the edge length sets
// the mesh size (0.0014 m: ~21k vertices, over a minute on 2 cores). Target: store + checkpoint
// time below 2% of the solve time.

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <iostream>

#include "bench/bench_options.hpp"
#include "db/job_store.hpp"
#include "jobs/direct_level_solver.hpp"
#include "jobs/job_executor.hpp"
#include "jobs/sweep_file.hpp"
#include "support/test_paths.hpp"

namespace {

std::string plate_scene(double edge_length, int frames) {
  return fmt::format(R"(name = "bench_plate"
gravity = [0, 0, 0]
[time]
step = 0.04
frames = {}
[[shell]]
name = "plate"
mesh = {{ generator = "sheet", width = 0.3, height = 0.3, edge_length = {}, structured = true }}
material = {{ youngs_modulus = 5e6, poisson_ratio = 0.45, density = 1100, thickness = 1e-3 }}
[[shell.pin]]
name = "clamp"
box = {{ min = [-0.151, -0.151, -0.001], max = [-0.149, 0.151, 0.001] }}
[[shell.load]]
kind = "line"
box = {{ min = [0.149, -0.151, -0.001], max = [0.151, 0.151, 0.001] }}
force = [0, 0, -2e-3]
)",
                     frames, edge_length);
}

double get(const std::map<std::string, double>& timings, const std::string& phase) {
  const auto found = timings.find(phase);
  return found == timings.end() ? 0.0 : found->second;
}

/// Runs the plate job and prints the overhead per level; the command line is read by
/// run_benchmark.
int bench_runner(const psq::bench::BenchOptions& options) {
  const double edge_length = options.number("edge-length");
  const int frames = options.integer("frames");
  const double snapshot_seconds = options.number("snapshot-seconds");
  if (snapshot_seconds < 0)
    psq::bench::reject_value("snapshot-seconds", fmt::format("{}", snapshot_seconds),
                             "a number >= 0");
  namespace fs = std::filesystem;
  using namespace psq;

  const fs::path dir = test::fresh_temp_dir("bench_runner");
  test::write_file(dir / "plate.toml", plate_scene(edge_length, frames));
  test::write_file(dir / "sweep.toml", "name = \"bench\"\nscene = \"plate.toml\"\n");
  const jobs::Sweep sweep = jobs::read_sweep(dir / "sweep.toml");
  db::JobStore store(dir / "psq.db");
  store.add_sweep(sweep.name, sweep.file.string(), jobs::new_jobs(sweep));
  const auto claim = store.claim_next({"bench:1", "host", "bench"}, 30.0);

  std::atomic<bool> stop{false};
  jobs::ExecutorEvents events;
  events.log = [](const std::string& line) { std::cerr << line << '\n'; };
  jobs::JobExecutor executor(
      store, dir / "psq.db", dir / "runs",
      [](const Scene& scene, db::Method method, int depth) {
        return jobs::make_level_solver(scene, method, depth);
      },
      {.snapshot_iterations = 50, .snapshot_seconds = snapshot_seconds, .code_version = "bench"},
      events, stop);
  const auto start = std::chrono::steady_clock::now();
  const jobs::RunOutcome outcome = executor.run(*claim);
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (outcome != jobs::RunOutcome::done) {
    std::cerr << "the job did not finish\n";
    return 1;
  }
  const db::JobResult result = store.results(db::JobSelection::job(claim->job.id)).front();
  std::cout << fmt::format("bench_runner: edge length {} m, {} frames, {:.1f} s in all\n",
                           edge_length, frames, total);
  std::cout << "level  iterations  solve[s]  database[s]  checkpoint[s]  database%  checkpoint%"
               "  overhead%\n";
  for (const db::LevelRecord& level : result.levels) {
    const double solve = get(level.timings, "assembly") + get(level.timings, "factorization") +
                         get(level.timings, "solve") + get(level.timings, "line_search");
    const double database = get(level.timings, "database");
    const double checkpoint = get(level.timings, "checkpoint");
    std::cout << fmt::format(
        "{:>5}  {:>10}  {:>8.2f}  {:>11.4f}  {:>13.4f}  {:>8.3f}%  {:>10.3f}%"
        "  {:>8.3f}%\n",
        level.level, level.iterations, solve, database, checkpoint, 100 * database / solve,
        100 * checkpoint / solve, 100 * (database + checkpoint) / solve);
  }
  std::cout << "(target: overhead below 2% for a job of over a minute)\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using psq::bench::OptionType;
  psq::bench::BenchOptions options(
      "bench_runner", {{"edge-length", OptionType::positive_number, "0.0014",
                        "plate mesh edge length [m]; 0.0014: ~21k vertices"},
                       {"frames", OptionType::count, "12", "frames of the job"},
                       {"snapshot-seconds", OptionType::number, "60",
                        "wall time between in-level snapshots [s]; 0: at every chance"}});
  return psq::bench::run_benchmark(options, argc, argv, bench_runner);
}
