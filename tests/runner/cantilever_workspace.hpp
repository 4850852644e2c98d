#pragma once
// A workspace for the `psq` command tests: a fresh directory holding the scene library's
// cantilever as scene.toml, a job store in it, and psq run against that store.

#include <fmt/format.h>

#include <filesystem>
#include <string>
#include <vector>

#include "db/job_store.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq::test {

struct CantileverWorkspace {
  std::filesystem::path dir;  ///< fresh for each workspace
  std::filesystem::path db;   ///< the job store, inside `dir`

  /// A new directory named after `name` with scene.toml in it; the store is `dir / store`.
  explicit CantileverWorkspace(const std::string& name,
                               const std::filesystem::path& store = "psq.db")
      : dir(fresh_temp_dir(name)), db(dir / store) {
    std::filesystem::copy_file(source_dir() / "jobs/scenes/cantilever.toml", dir / "scene.toml");
  }

  /// `psq arguments... --db <db>`.
  ProcessResult psq(std::vector<std::string> arguments) const {
    arguments.insert(arguments.end(), {"--db", db.string()});
    return run_psq(arguments);
  }

  /// Writes `<name>.toml`, the sweep `name` of scene.toml whose [grid] table is `grid` (TOML
  /// lines; tables after it, such as [[zip]], may follow), and adds it with `psq sweep add`.
  ProcessResult add_sweep(const std::string& name, const std::string& grid) const {
    const std::filesystem::path file =
        write_file(dir / (name + ".toml"),
                   fmt::format("name = \"{}\"\nscene = \"scene.toml\"\n[grid]\n{}", name, grid));
    return psq({"sweep", "add", file.string()});
  }

  /// Every job of the store with its level records, in the order they were added.
  std::vector<db::JobResult> results() const {
    return db::JobStore(db).results(db::JobSelection::all());
  }
};

}  // namespace psq::test
