#pragma once
// A job's identity: the hash of its canonical parameters (the scene file's content, the
// parameter overrides, the hierarchy depth). The same parameters always give the same id, so
// adding a sweep again, or extending it, adds only jobs that are really new.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "db/job_records.hpp"

namespace psq::jobs {

/// Scene parameter overrides by dotted path ("shell.cloth.material.thickness" → 5e-4). A std::map
/// keeps the paths sorted, which the canonical form relies on. Values are canonical numbers:
/// real parameters are stored as doubles and integer ones as integers (see
/// SceneDocument::canonical_override, jobs/scene_overrides.hpp).
using Overrides = std::map<std::string, nlohmann::json>;

/// checksum_text of a file's bytes: "fnv1a64:<16 hex digits>". Throws InputError if it cannot
/// be read.
std::string file_content_hash(const std::filesystem::path& file);

/// The canonical parameters of a job:
///   {"depth": d, "overrides": {path: value, ...}, "scene": "<scene content hash>"}
/// and "method": "<name>" when the method is not the one its depth implies
/// (db::method_of_depth), so that direct and progressive jobs keep the ids they had before
/// methods existed. `depth` is the hierarchy depth (1 for a direct job).
/// nlohmann::json objects keep keys sorted, and compact dumps print doubles in the shortest
/// form that reads back exactly, so equal parameters always dump to equal text.
nlohmann::json canonical_parameters(const std::string& scene_hash, const Overrides& overrides,
                                    int depth, db::Method method);

/// The depth of a job's hierarchy, from its canonical parameters: its levels for a progressive
/// job, the hierarchy whose coarsest level a coarse-prolonged job solves, 1 for a direct job.
int hierarchy_depth(const db::Job& job);

/// The job id: 16 hex digits of the 64-bit FNV-1a hash of the compact dump of the canonical
/// parameters. Not cryptographic; with n jobs the chance of any collision is about n²/2⁶⁵
/// (3e-8 for a million jobs), and the store refuses an id stored with other parameters, so a
/// collision is reported, never silently merged.
std::string job_id(const nlohmann::json& canonical);

}  // namespace psq::jobs
