// `psq hierarchy` end to end.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "engine/mesh/mesh_io.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

TEST(HierarchyCommand, WritesEveryLevelAndStatisticsWithExactRestShapes) {
  const auto dir = test::fresh_temp_dir("hierarchy_command");
  const auto bunny = test::shared_dir() / "data/meshes/bunny.obj";
  const auto result = test::run_psq(
      {"hierarchy", bunny.string(), "--levels", "3", "--ratio", "0.3", "--out", dir.string()});
  ASSERT_EQ(result.exit_code, 0) << result.errors;
  std::ifstream in(dir / "hierarchy.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  const auto& levels = summary.at("levels");
  ASSERT_EQ(levels.size(), 3u);
  const TriMesh finest = read_mesh(bunny);
  for (int l = 0; l < 3; ++l) {
    const auto& level = levels[l];
    EXPECT_EQ(level.at("level").get<int>(), l);
    EXPECT_LT(level.at("rest_error").get<double>(), 1e-10) << "level " << l;
    EXPECT_GE(level.at("min_angle_degrees").get<double>(), 0.0);
    EXPECT_GE(level.at("max_aspect_ratio").get<double>(), 1.0);
    const TriMesh written = read_mesh(dir / ("level_" + std::to_string(l) + ".obj"));
    EXPECT_EQ(written.vertex_count(), level.at("vertices").get<int>());
    EXPECT_EQ(written.triangle_count(), level.at("triangles").get<int>());
  }
  EXPECT_EQ(levels[2].at("vertices").get<int>(), finest.vertex_count());
  EXPECT_LT(levels[0].at("vertices").get<int>(), levels[1].at("vertices").get<int>());
  EXPECT_LT(levels[1].at("vertices").get<int>(), finest.vertex_count());
}

TEST(HierarchyCommand, BadParametersExitOneNamingTheParameter) {
  const auto dir = test::fresh_temp_dir("hierarchy_command_bad");
  const auto bunny = (test::shared_dir() / "data/meshes/bunny.obj").string();
  const auto levels = test::run_psq({"hierarchy", bunny, "--levels", "0", "--out", dir.string()});
  EXPECT_EQ(levels.exit_code, 1);
  EXPECT_NE(levels.errors.find("--levels"), std::string::npos) << levels.errors;
  const auto ratio =
      test::run_psq({"hierarchy", bunny, "--ratio", "1.5", "--out", dir.string()});
  EXPECT_EQ(ratio.exit_code, 1);
  EXPECT_NE(ratio.errors.find("--ratio"), std::string::npos) << ratio.errors;
  const auto missing =
      test::run_psq({"hierarchy", (dir / "none.obj").string(), "--out", dir.string()});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.errors.find("none.obj"), std::string::npos) << missing.errors;
}

}  // namespace
}  // namespace psq
