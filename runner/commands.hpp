#pragma once
#include <CLI/CLI.hpp>

namespace psq::runner {

inline constexpr int kExitInputError = 1;
inline constexpr int kExitNumericalError = 2;
inline constexpr int kExitNotConverged = 3;
inline constexpr int kExitInternalError = 4;

/// Adds `psq sim SCENE --out DIR`.
void register_sim_command(CLI::App& app);

/// Runs the subcommand the user chose; returns the process exit code.
int run_selected_command(CLI::App& app);

}  // namespace psq::runner
