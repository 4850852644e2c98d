#include "runner/workspace.hpp"

#include <cstdlib>

namespace psq::runner {

std::filesystem::path database_path(const std::string& option) {
  if (!option.empty()) return option;
  const char* from_environment = std::getenv("PSQ_DB");
  if (from_environment && *from_environment) return from_environment;
  return std::filesystem::path(".psq") / "psq.db";
}

void add_database_option(CLI::App& command, std::string& path) {
  command.add_option("--db", path,
                     "Job store (SQLite); default $PSQ_DB, else .psq/psq.db in the current "
                     "directory");
}

}  // namespace psq::runner
