#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace psq::runner {

inline constexpr int kExitInputError = 1;
inline constexpr int kExitNumericalError = 2;
inline constexpr int kExitNotConverged = 3;
inline constexpr int kExitInternalError = 4;

/// A subcommand and what runs it (returning the process exit code).
struct Command {
  CLI::App* app;
  std::function<int()> run;
};

/// Each adds one subcommand to `app` and its runner to `commands`.
void register_sim_command(CLI::App& app, std::vector<Command>& commands);
void register_check_command(CLI::App& app, std::vector<Command>& commands);
void register_ccd_bench_command(CLI::App& app, std::vector<Command>& commands);
void register_sweep_command(CLI::App& app, std::vector<Command>& commands);
void register_status_command(CLI::App& app, std::vector<Command>& commands);
void register_work_command(CLI::App& app, std::vector<Command>& commands);
void register_resume_command(CLI::App& app, std::vector<Command>& commands);
void register_results_command(CLI::App& app, std::vector<Command>& commands);
void register_cancel_command(CLI::App& app, std::vector<Command>& commands);
void register_retry_command(CLI::App& app, std::vector<Command>& commands);
void register_promote_command(CLI::App& app, std::vector<Command>& commands);
void register_report_command(CLI::App& app, std::vector<Command>& commands);
void register_hierarchy_command(CLI::App& app, std::vector<Command>& commands);
void register_slurm_command(CLI::App& app, std::vector<Command>& commands);

}  // namespace psq::runner
