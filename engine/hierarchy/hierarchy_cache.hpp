#pragma once
// On-disk cache of built hierarchies (DESIGN.md §3): a sweep over material or thickness
// builds the hierarchy of a mesh once. One binary file per key, written atomically and
// checked on every read; a damaged, truncated or foreign file is rebuilt, never trusted.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/hierarchy/mesh_hierarchy.hpp"

namespace psq {

/// Raised whenever the file layout or the decimation rules change, so old files rebuild.
inline constexpr std::uint32_t kHierarchyCacheVersion = 2;  // 2: with the collapse order

/// What load_or_build_hierarchy did.
enum class HierarchyCacheOutcome {
  kHit,      ///< read a valid file
  kBuilt,    ///< no file: built and stored
  kRebuilt,  ///< a file was there but unusable (damaged, truncated, foreign): rebuilt
};

/// One hierarchy obtained through the cache: what the cache did and how long it took (reading
/// the file on a hit; building and storing it otherwise), so that a job store can account the
/// time its hits saved.
struct HierarchyCacheUse {
  std::uint64_t key = 0;
  HierarchyCacheOutcome outcome = HierarchyCacheOutcome::kBuilt;
  double seconds = 0.0;
};

/// 64-bit key of everything the hierarchy depends on: finest positions and triangles, pins
/// (empty = all free), settings, the decimation bounds and kHierarchyCacheVersion.
std::uint64_t hierarchy_cache_key(const TriMesh& finest, const std::vector<int>& pin_group,
                                  const HierarchySettings& settings);

/// The cache file of a key inside `cache_dir`: hierarchy-<16 hex digits>.bin.
std::filesystem::path hierarchy_cache_file(const std::filesystem::path& cache_dir,
                                           std::uint64_t key);

/// The file image: magic "PSQHIER\0", version, key, payload size, payload (native byte
/// order), then a 64-bit checksum of everything before it.
std::string serialize_hierarchy(const MeshHierarchy& hierarchy, std::uint64_t key);

/// The hierarchy in a file image, or nothing if the image is not a complete, undamaged
/// image for `key` whose finest level is `finest` and whose indices are all in range.
std::optional<MeshHierarchy> deserialize_hierarchy(std::string_view image, std::uint64_t key,
                                                   const TriMesh& finest);

/// build_hierarchy through the cache in `cache_dir` (created if missing). Throws what
/// build_hierarchy throws, and InputError naming the directory if it cannot be written.
MeshHierarchy load_or_build_hierarchy(const TriMesh& finest, const std::vector<int>& pin_group,
                                      const HierarchySettings& settings,
                                      const std::filesystem::path& cache_dir,
                                      HierarchyCacheOutcome* outcome = nullptr);

}  // namespace psq
