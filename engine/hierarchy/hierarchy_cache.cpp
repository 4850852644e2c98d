#include "engine/hierarchy/hierarchy_cache.hpp"

#include <fmt/format.h>

#include <algorithm>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <span>
#include <sstream>
#include <system_error>

#include "engine/core/atomic_file.hpp"
#include "engine/core/checksum.hpp"
#include "engine/core/error.hpp"

namespace psq {

namespace {

constexpr char kMagic[8] = {'P', 'S', 'Q', 'H', 'I', 'E', 'R', '\0'};
constexpr double kBarycentricTolerance = 1e-9;

/// FNV-1a over the raw bytes of values and arrays, for the cache key.
class Hash {
 public:
  Hash& bytes(const void* data, std::size_t size) {
    fnv_.update(std::span(static_cast<const std::byte*>(data), size));
    return *this;
  }
  template <typename T>
  Hash& value(const T& v) {
    return bytes(&v, sizeof v);
  }
  [[nodiscard]] std::uint64_t result() const { return fnv_.value(); }

 private:
  Fnv1a64 fnv_;
};

class Writer {
 public:
  template <typename T>
  void value(const T& v) {
    out_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <typename T>
  void array(const T* data, std::size_t count) {
    value<std::uint64_t>(count);
    out_.append(reinterpret_cast<const char*>(data), count * sizeof(T));
  }
  void locations(const std::vector<SurfaceLocation>& locations) {
    value<std::uint64_t>(locations.size());
    for (const auto& l : locations) {
      value<std::int32_t>(l.triangle);
      array(l.barycentric.data(), 3);
    }
  }
  std::string& text() { return out_; }

 private:
  std::string out_;
};

/// Reads what Writer wrote; any read past the end sets failed() and yields zeros.
class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  template <typename T>
  T value() {
    T v{};
    take(&v, sizeof v);
    return v;
  }
  template <typename T>
  std::vector<T> array() {
    const auto count = value<std::uint64_t>();
    if (failed_ || count > (in_.size() - at_) / sizeof(T)) {
      failed_ = true;
      return {};
    }
    std::vector<T> v(count);
    take(v.data(), count * sizeof(T));
    return v;
  }
  template <typename Matrix>
  Matrix rows_of_three() {
    const auto flat = array<typename Matrix::Scalar>();
    if (flat.size() % 3 != 0) failed_ = true;
    Matrix m(flat.size() / 3, 3);
    if (!flat.empty()) std::memcpy(m.data(), flat.data(), flat.size() * sizeof(flat[0]));
    return m;
  }
  std::vector<SurfaceLocation> locations() {
    const auto count = value<std::uint64_t>();
    if (failed_ || count > (in_.size() - at_) / (sizeof(std::int32_t) + 3 * sizeof(double))) {
      failed_ = true;
      return {};
    }
    std::vector<SurfaceLocation> result(count);
    for (auto& l : result) {
      l.triangle = value<std::int32_t>();
      const auto b = array<double>();
      if (b.size() != 3) {
        failed_ = true;
        return {};
      }
      l.barycentric = Eigen::Vector3d(b[0], b[1], b[2]);
    }
    return result;
  }
  [[nodiscard]] bool failed() const { return failed_; }
  [[nodiscard]] bool at_end() const { return at_ == in_.size(); }

 private:
  void take(void* out, std::size_t size) {
    if (failed_ || size > in_.size() - at_) {
      failed_ = true;
      return;
    }
    // An empty array's data() may be null, and memcpy takes no null pointer even for 0 bytes.
    if (size == 0) return;
    std::memcpy(out, in_.data() + at_, size);
    at_ += size;
  }
  std::string_view in_;
  std::size_t at_ = 0;
  bool failed_ = false;
};

void write_level(Writer& w, const HierarchyLevel& level) {
  w.array(level.rest.vertices.data(), level.rest.vertices.size());
  w.array(level.rest.triangles.data(), level.rest.triangles.size());
  w.array(level.pin_group.data(), level.pin_group.size());
  w.locations(level.finest);
  w.locations(level.next_finer);
  w.array(level.parent.data(), level.parent.size());
  w.array(level.expansion_color.data(), level.expansion_color.size());
  std::vector<int> collapses;
  for (const auto& [removed, survivor] : level.collapses) collapses.insert(collapses.end(), {removed, survivor});
  w.array(collapses.data(), collapses.size());
}

HierarchyLevel read_level(Reader& r) {
  HierarchyLevel level;
  level.rest.vertices = r.rows_of_three<Positions>();
  level.rest.triangles = r.rows_of_three<Triangles>();
  level.pin_group = r.array<int>();
  level.finest = r.locations();
  level.next_finer = r.locations();
  level.parent = r.array<int>();
  level.expansion_color = r.array<int>();
  const std::vector<int> collapses = r.array<int>();
  if (collapses.size() % 2 != 0) return {};  // rejected by valid_hierarchy (no rest mesh)
  for (std::size_t i = 0; i < collapses.size(); i += 2)
    level.collapses.push_back({collapses[i], collapses[i + 1]});
  return level;
}

bool valid_locations(const std::vector<SurfaceLocation>& locations, std::size_t expected,
                     int triangle_count) {
  if (locations.size() != expected) return false;
  for (const auto& l : locations) {
    if (l.triangle < 0 || l.triangle >= triangle_count || !l.barycentric.allFinite() ||
        l.barycentric.minCoeff() < -kBarycentricTolerance ||
        std::abs(l.barycentric.sum() - 1) > kBarycentricTolerance) {
      return false;
    }
  }
  return true;
}

bool all_in_range(const std::vector<int>& values, int end) {
  for (const int v : values) {
    if (v < 0 || v >= end) return false;
  }
  return true;
}

/// Every index in range and every size consistent, so that no later use can go out of bounds.
bool valid_hierarchy(const MeshHierarchy& h, const TriMesh& finest) {
  if (h.level_count() < 1) return false;
  const TriMesh& top = h.finest().rest;
  if (top.vertices != finest.vertices || top.triangles != finest.triangles) return false;
  for (int l = 0; l < h.level_count(); ++l) {
    const HierarchyLevel& level = h.levels[l];
    const int n = level.rest.vertex_count();
    const bool is_finest = l + 1 == h.level_count();
    const std::size_t finer = is_finest ? 0 : h.levels[l + 1].rest.vertex_count();
    if (level.rest.triangles.size() > 0 &&
        (level.rest.triangles.minCoeff() < 0 || level.rest.triangles.maxCoeff() >= n)) {
      return false;
    }
    if (!level.rest.vertices.allFinite() || level.pin_group.size() != static_cast<std::size_t>(n) ||
        !valid_locations(level.finest, finest.vertex_count(), level.rest.triangle_count()) ||
        !valid_locations(level.next_finer, finer, level.rest.triangle_count()) ||
        level.parent.size() != finer || !all_in_range(level.parent, n) ||
        level.expansion_color.size() != (is_finest ? 0u : static_cast<std::size_t>(n)) ||
        !all_in_range(level.expansion_color, std::max(n, 1)) ||
        level.collapses.size() != (is_finest ? 0u : finer - static_cast<std::size_t>(n)) ||
        !std::all_of(level.collapses.begin(), level.collapses.end(), [&](const auto& c) {
          return c[0] >= 0 && c[1] >= 0 && static_cast<std::size_t>(c[0]) < finer &&
                 static_cast<std::size_t>(c[1]) < finer;
        })) {
      return false;
    }
  }
  return true;
}

std::uint64_t checksum(std::string_view bytes) { return Fnv1a64().update(bytes).value(); }

std::string read_whole_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

std::uint64_t hierarchy_cache_key(const TriMesh& finest, const std::vector<int>& pin_group,
                                  const HierarchySettings& settings) {
  Hash hash;
  hash.value(kHierarchyCacheVersion)
      .value(kHierarchyMinAngleDegrees)
      .value(kHierarchyMaxNormalChangeDegrees)
      .value(kHierarchyCornerDegrees)
      .value(settings.levels)
      .value(settings.vertex_ratio)
      .value(settings.allow_fewer_levels)
      .value(static_cast<std::int64_t>(finest.vertex_count()))
      .bytes(finest.vertices.data(), finest.vertices.size() * sizeof(double))
      .value(static_cast<std::int64_t>(finest.triangle_count()))
      .bytes(finest.triangles.data(), finest.triangles.size() * sizeof(int));
  // An empty pin list means all free: hash it like the explicit list.
  for (int v = 0; v < finest.vertex_count(); ++v) {
    hash.value(pin_group.empty() ? kFreeVertex : pin_group[v]);
  }
  return hash.result();
}

std::filesystem::path hierarchy_cache_file(const std::filesystem::path& cache_dir,
                                           std::uint64_t key) {
  return cache_dir / fmt::format("hierarchy-{:016x}.bin", key);
}

std::string serialize_hierarchy(const MeshHierarchy& hierarchy, std::uint64_t key) {
  Writer payload;
  payload.value<std::uint64_t>(hierarchy.levels.size());
  for (const HierarchyLevel& level : hierarchy.levels) write_level(payload, level);
  Writer image;
  image.text().append(kMagic, sizeof kMagic);
  image.value(kHierarchyCacheVersion);
  image.value(key);
  image.value<std::uint64_t>(payload.text().size());
  image.text() += payload.text();
  image.value(checksum(image.text()));
  return std::move(image.text());
}

std::optional<MeshHierarchy> deserialize_hierarchy(std::string_view image, std::uint64_t key,
                                                   const TriMesh& finest) {
  constexpr std::size_t kChecksumSize = sizeof(std::uint64_t);
  if (image.size() < sizeof kMagic + kChecksumSize) return std::nullopt;
  const std::string_view body = image.substr(0, image.size() - kChecksumSize);
  Reader trailer(image.substr(body.size()));
  if (trailer.value<std::uint64_t>() != checksum(body)) return std::nullopt;
  if (std::memcmp(body.data(), kMagic, sizeof kMagic) != 0) return std::nullopt;

  Reader r(body.substr(sizeof kMagic));
  if (r.value<std::uint32_t>() != kHierarchyCacheVersion || r.value<std::uint64_t>() != key) {
    return std::nullopt;
  }
  r.value<std::uint64_t>();  // payload size: implied by the checksummed length
  MeshHierarchy hierarchy;
  const auto level_count = r.value<std::uint64_t>();
  for (std::uint64_t l = 0; l < level_count && !r.failed(); ++l) {
    hierarchy.levels.push_back(read_level(r));
  }
  if (r.failed() || !r.at_end() || !valid_hierarchy(hierarchy, finest)) return std::nullopt;
  return hierarchy;
}

MeshHierarchy load_or_build_hierarchy(const TriMesh& finest, const std::vector<int>& pin_group,
                                      const HierarchySettings& settings,
                                      const std::filesystem::path& cache_dir,
                                      HierarchyCacheOutcome* outcome) {
  const std::uint64_t key = hierarchy_cache_key(finest, pin_group, settings);
  const std::filesystem::path file = hierarchy_cache_file(cache_dir, key);
  std::error_code error;
  const bool existed = std::filesystem::exists(file, error);
  if (existed) {
    if (auto cached = deserialize_hierarchy(read_whole_file(file), key, finest)) {
      if (outcome) *outcome = HierarchyCacheOutcome::kHit;
      return std::move(*cached);
    }
  }
  MeshHierarchy hierarchy = build_hierarchy(finest, pin_group, settings);
  std::filesystem::create_directories(cache_dir, error);
  if (error) {
    throw InputError(fmt::format("hierarchy cache {}: cannot create the directory: {}",
                                 cache_dir.string(), error.message()));
  }
  const std::string image = serialize_hierarchy(hierarchy, key);
  write_file_atomically(file, [&](std::ostream& out) { out.write(image.data(), image.size()); });
  if (outcome) *outcome = existed ? HierarchyCacheOutcome::kRebuilt : HierarchyCacheOutcome::kBuilt;
  return hierarchy;
}

}  // namespace psq
