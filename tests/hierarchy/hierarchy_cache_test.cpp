#include "engine/hierarchy/hierarchy_cache.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "engine/mesh/generators.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

const TriMesh& cache_mesh() {
  static const TriMesh mesh = make_sphere({.radius = 0.5, .edge_length = 0.15});
  return mesh;
}

constexpr HierarchySettings kSettings{.levels = 3, .vertex_ratio = 0.3};

void expect_identical(const MeshHierarchy& a, const MeshHierarchy& b) {
  ASSERT_EQ(a.level_count(), b.level_count());
  for (int l = 0; l < a.level_count(); ++l) {
    const HierarchyLevel& x = a.levels[l];
    const HierarchyLevel& y = b.levels[l];
    EXPECT_EQ(x.rest.vertices, y.rest.vertices);
    EXPECT_EQ(x.rest.triangles, y.rest.triangles);
    EXPECT_EQ(x.pin_group, y.pin_group);
    EXPECT_EQ(x.parent, y.parent);
    EXPECT_EQ(x.expansion_color, y.expansion_color);
    EXPECT_EQ(x.collapses, y.collapses);
    ASSERT_EQ(x.finest.size(), y.finest.size());
    for (std::size_t i = 0; i < x.finest.size(); ++i) {
      EXPECT_EQ(x.finest[i].triangle, y.finest[i].triangle);
      EXPECT_EQ(x.finest[i].barycentric, y.finest[i].barycentric);
    }
    ASSERT_EQ(x.next_finer.size(), y.next_finer.size());
    for (std::size_t i = 0; i < x.next_finer.size(); ++i) {
      EXPECT_EQ(x.next_finer[i].triangle, y.next_finer[i].triangle);
      EXPECT_EQ(x.next_finer[i].barycentric, y.next_finer[i].barycentric);
    }
  }
}

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
}

TEST(HierarchyCache, SecondCallIsAHitWithAnIdenticalHierarchy) {
  const auto dir = test::fresh_temp_dir("hierarchy_cache_hit");
  HierarchyCacheOutcome outcome{};
  const MeshHierarchy built = load_or_build_hierarchy(cache_mesh(), {}, kSettings, dir, &outcome);
  EXPECT_EQ(outcome, HierarchyCacheOutcome::kBuilt);
  const auto file = hierarchy_cache_file(dir, hierarchy_cache_key(cache_mesh(), {}, kSettings));
  ASSERT_TRUE(std::filesystem::exists(file));
  const auto written = std::filesystem::last_write_time(file);

  const MeshHierarchy cached = load_or_build_hierarchy(cache_mesh(), {}, kSettings, dir, &outcome);
  EXPECT_EQ(outcome, HierarchyCacheOutcome::kHit);
  EXPECT_EQ(std::filesystem::last_write_time(file), written);
  expect_identical(cached, built);
}

TEST(HierarchyCache, KeyDependsOnMeshPinsAndSettings) {
  const std::uint64_t key = hierarchy_cache_key(cache_mesh(), {}, kSettings);
  EXPECT_EQ(key, hierarchy_cache_key(cache_mesh(),
                                     std::vector<int>(cache_mesh().vertex_count(), kFreeVertex),
                                     kSettings));
  TriMesh moved = cache_mesh();
  moved.vertices(0, 0) += 1e-12;
  EXPECT_NE(key, hierarchy_cache_key(moved, {}, kSettings));
  std::vector<int> pins(cache_mesh().vertex_count(), kFreeVertex);
  pins[5] = 0;
  EXPECT_NE(key, hierarchy_cache_key(cache_mesh(), pins, kSettings));
  EXPECT_NE(key, hierarchy_cache_key(cache_mesh(), {}, {.levels = 2, .vertex_ratio = 0.3}));
  EXPECT_NE(key, hierarchy_cache_key(cache_mesh(), {}, {.levels = 3, .vertex_ratio = 0.25}));
  HierarchySettings fewer = kSettings;
  fewer.allow_fewer_levels = true;
  EXPECT_NE(key, hierarchy_cache_key(cache_mesh(), {}, fewer));
}

TEST(HierarchyCache, DamagedTruncatedOrForeignFilesAreRebuilt) {
  const auto dir = test::fresh_temp_dir("hierarchy_cache_damage");
  const MeshHierarchy built = load_or_build_hierarchy(cache_mesh(), {}, kSettings, dir);
  const auto file = hierarchy_cache_file(dir, hierarchy_cache_key(cache_mesh(), {}, kSettings));
  const std::string good = test::read_file(file);

  std::string flipped = good;
  flipped[flipped.size() / 2] ^= 0x10;
  // The image of another mesh under this key's name: complete and undamaged, but foreign.
  const TriMesh other = make_sphere({.radius = 0.4, .edge_length = 0.15});
  const std::string foreign = serialize_hierarchy(build_hierarchy(other, {}, kSettings),
                                                  hierarchy_cache_key(other, {}, kSettings));
  for (const std::string& bad : {flipped, good.substr(0, good.size() - 9), std::string("junk"),
                                 std::string(), foreign}) {
    write_bytes(file, bad);
    HierarchyCacheOutcome outcome{};
    const MeshHierarchy again = load_or_build_hierarchy(cache_mesh(), {}, kSettings, dir, &outcome);
    EXPECT_EQ(outcome, HierarchyCacheOutcome::kRebuilt);
    expect_identical(again, built);
    EXPECT_EQ(test::read_file(file), good);  // the rebuilt file replaced the bad one
  }
}

TEST(HierarchyCache, EveryTruncationIsRejected) {
  const MeshHierarchy built = build_hierarchy(cache_mesh(), {}, kSettings);
  const std::uint64_t key = hierarchy_cache_key(cache_mesh(), {}, kSettings);
  const std::string image = serialize_hierarchy(built, key);
  ASSERT_TRUE(deserialize_hierarchy(image, key, cache_mesh()).has_value());
  EXPECT_FALSE(deserialize_hierarchy(image, key + 1, cache_mesh()).has_value());
  for (std::size_t length = 0; length < image.size(); length += 97) {
    EXPECT_FALSE(deserialize_hierarchy(image.substr(0, length), key, cache_mesh()).has_value());
  }
}

}  // namespace
}  // namespace psq
