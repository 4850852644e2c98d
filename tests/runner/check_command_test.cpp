// `psq check` end to end: a scene whose shells cross is refused with the crossing triangles
// named; scenes whose shells are apart, and the scene library, pass.

#include <gtest/gtest.h>

#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// A 1 m floor in z = 0 and a 0.2 m wall standing upright (rotated 90° about x, so its
/// local y is the height z) at y = −0.4, x ∈ [0.15, 0.35], lifted by `lift`; both are 2 × 2
/// squares of two triangles each (8 triangles). Floor triangle 2 is the lower-left half of
/// the square x ∈ [0, 0.5], y ∈ [−0.5, 0]: with local coordinates u = 2x, v = 2y + 1 it is
/// u + v ≤ 1, and the wall's foot (v = 0.2, u ∈ [0.3, 0.7]) lies strictly inside it. Lifted
/// by 0.05, the floor plane cuts the wall at its local y = −0.05, halfway up its lower row of
/// squares, whose four triangles (0 to 3) each cross it along a segment; the upper row stays
/// above the floor.
std::string floor_and_wall(double lift) {
  const std::string material =
      "material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 500, "
      "thickness = 1e-3 }\n";
  const auto sheet = [](double size, double edge) {
    return "mesh = { generator = \"sheet\", width = " + std::to_string(size) +
           ", height = " + std::to_string(size) + ", edge_length = " + std::to_string(edge) +
           ", structured = true }\n";
  };
  return "name = \"floor_and_wall\"\n"
         "[[shell]]\nname = \"floor\"\n" +
         sheet(1.0, 0.5) + material + "[[shell]]\nname = \"wall\"\n" + sheet(0.2, 0.1) +
         "placement = { rotation_axis = [1, 0, 0], rotation_degrees = 90, "
         "translation = [0.25, -0.4, " +
         std::to_string(lift) + "] }\n" + material;
}

TEST(CheckCommand, CrossingShellsAreListedByShellAndTriangleAndExitOne) {
  const auto dir = test::fresh_temp_dir("check");
  const auto scene = test::write_file(dir / "crossing.toml", floor_and_wall(0.05));
  const auto result = test::run_psq({"check", scene.string()});
  EXPECT_EQ(result.exit_code, 1) << result.output << result.errors;
  EXPECT_EQ(result.output,
            "4 intersecting triangle pairs:\n"
            "  shell 'floor' triangle 2 and shell 'wall' triangle 0\n"
            "  shell 'floor' triangle 2 and shell 'wall' triangle 1\n"
            "  shell 'floor' triangle 2 and shell 'wall' triangle 2\n"
            "  shell 'floor' triangle 2 and shell 'wall' triangle 3\n");
  EXPECT_NE(result.errors.find("crossing.toml"), std::string::npos) << result.errors;
  EXPECT_NE(result.errors.find("not free of intersections"), std::string::npos) << result.errors;
}

TEST(CheckCommand, SimRefusesToStartFromAnIntersectingStateAndWritesNothing) {
  const auto dir = test::fresh_temp_dir("check");
  const auto scene = test::write_file(dir / "crossing.toml", floor_and_wall(0.05));
  const auto result = test::run_psq({"sim", scene.string(), "--out", (dir / "out").string()});
  EXPECT_EQ(result.exit_code, 1) << result.errors;
  EXPECT_NE(result.errors.find("crossing.toml: initial state"), std::string::npos) << result.errors;
  EXPECT_NE(result.errors.find("shell 'floor' triangle 2 and shell 'wall' triangle 0"),
            std::string::npos)
      << result.errors;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(CheckCommand, ShellsApartPass) {
  const auto dir = test::fresh_temp_dir("check");
  const auto scene = test::write_file(dir / "apart.toml", floor_and_wall(0.2));
  const auto result = test::run_psq({"check", scene.string()});
  EXPECT_EQ(result.exit_code, 0) << result.output << result.errors;
  EXPECT_EQ(result.output, "no intersections (16 triangles)\n");
}

TEST(CheckCommand, EverySceneOfTheLibraryStartsFreeOfIntersections) {
  int scenes = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(test::source_dir() / "jobs" / "scenes")) {
    if (entry.path().extension() != ".toml") continue;
    ++scenes;
    const auto result = test::run_psq({"check", entry.path().string()});
    EXPECT_EQ(result.exit_code, 0) << entry.path() << "\n" << result.output << result.errors;
    EXPECT_EQ(result.output.rfind("no intersections (", 0), 0u) << entry.path() << result.output;
  }
  EXPECT_GT(scenes, 0);
}

TEST(CheckCommand, MissingSceneIsAnInputError) {
  const auto result = test::run_psq({"check", "/nonexistent/scene.toml"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("/nonexistent/scene.toml"), std::string::npos) << result.errors;
}

}  // namespace
}  // namespace psq
