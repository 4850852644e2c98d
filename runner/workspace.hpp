#pragma once
// Where psq keeps its state: the workspace directory `.psq/` in the current directory, with
// the job store `.psq/psq.db`. `--db PATH` or the PSQ_DB environment variable choose another
// store.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>

namespace psq::runner {

/// The job store's path: `option` if given, else $PSQ_DB if set and not empty, else
/// .psq/psq.db in the current directory.
std::filesystem::path database_path(const std::string& option);

/// Adds `--db PATH` to a subcommand, filling `path`.
void add_database_option(CLI::App& command, std::string& path);

}  // namespace psq::runner
