#pragma once
// Sweep files (TOML, docs/sweep-format.md): a base scene and variations of its numbers,
// expanded into jobs. Every job is validated by putting its overrides into the base scene's
// document and reading it (jobs/scene_overrides.hpp) before anything is stored, so a bad
// value is reported at its line and no job of the sweep is added.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "db/job_records.hpp"
#include "jobs/job_identity.hpp"

namespace psq::jobs {

/// One expanded job of a sweep.
struct SweepJob {
  Overrides overrides;  ///< canonical values (see canonical_override)
  int depth = 1;        ///< hierarchy levels (1 for a direct job)
  db::Method method = db::Method::direct;
  nlohmann::json parameters;  ///< canonical_parameters(scene hash, overrides, depth, method)
  std::string id;             ///< job_id(parameters)
  /// The levels the job solves and records: its hierarchy's for a progressive job, else one.
  int levels() const { return method == db::Method::progressive ? depth : 1; }
};

/// A sweep file, expanded.
struct Sweep {
  std::string name;
  std::filesystem::path file;   ///< the sweep file, absolute
  std::filesystem::path scene;  ///< the base scene file, absolute and normalized
  std::string scene_hash;       ///< file_content_hash(scene)
  /// The jobs in expansion order: the cartesian product of the [grid] lists and the [[zip]]
  /// groups, in the order the axes are listed below, the last axis varying fastest. Grid
  /// axes come first (sorted by path, as TOML tables are unordered), then the zip groups in
  /// file order.
  std::vector<SweepJob> jobs;
  /// What follows the previews (`refine`; docs/sweep-format.md, "Coarse-first sweeps").
  db::RefineRule refine;
};

/// Reads and expands a sweep file; reads its scene and applies every job's overrides to it.
/// Throws InputError "file:line: message" for: TOML syntax errors, unknown keys (with the
/// nearest valid key), a missing name or scene, a scene file that does not exist or is
/// invalid (reported in the scene file), unknown parameter paths (with the nearest valid
/// path), paths to something other than a number and `hierarchy.levels` (a job's levels are
/// its depth), lists that are empty or not lists, zipped lists of different lengths, a path
/// varied twice, two jobs with the same parameters, more than 10 000 jobs, and values the
/// scene reader refuses (reported at the value's line with the first job that has it and the
/// reader's rule, e.g. negative thickness, ν ≥ 0.5; depth 0).
Sweep read_sweep(const std::filesystem::path& file);

/// read_sweep on `text` as if it were the content of the sweep file `file` (which need not
/// exist): messages name `file` and the scene is resolved relative to its directory. For
/// callers that hold the text already, such as the fuzz target.
Sweep read_sweep_text(std::string_view text, const std::filesystem::path& file);

/// "depth=1 method=direct shell.cloth.material.thickness=0.0005 ...": a job's parameters on one
/// line, paths sorted.
std::string describe_parameters(const SweepJob& job);

/// The jobs of a sweep as the store takes them.
std::vector<db::NewJob> new_jobs(const Sweep& sweep);

}  // namespace psq::jobs
