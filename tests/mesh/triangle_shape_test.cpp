// Shape quality of a shell's triangles (engine/mesh/triangle_shape.hpp): the measure against
// triangles whose heights are known, and the refusal of slivers naming the worst one.

#include "engine/mesh/triangle_shape.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "engine/core/error.hpp"

namespace psq {
namespace {

TEST(TriangleShape, QualityIsTheHeightOverTheLongestEdge) {
  // Equilateral of side 2: height √3, so √3 / 2.
  EXPECT_NEAR(triangle_shape_quality({0, 0, 0}, {2, 0, 0}, {1, std::sqrt(3.0), 0}),
              std::sqrt(3.0) / 2, 1e-15);
  // A needle: a 1e-6 wide base under a unit height; its longest edge is √(1 + 1e-12) ≈ 1 and
  // the height onto it is about the base, 1e-6.
  EXPECT_NEAR(triangle_shape_quality({0, 0, 0}, {1e-6, 0, 0}, {0, 1, 0}), 1e-6, 1e-15);
  // A cap: base 2 with its apex 1e-7 above the middle; height 1e-7 over the base 2.
  EXPECT_NEAR(triangle_shape_quality({-1, 0, 0}, {1, 0, 0}, {0, 1e-7, 0}), 0.5e-7, 1e-20);
  // The measure has no unit: the same needle a million times larger.
  EXPECT_NEAR(triangle_shape_quality({0, 0, 0}, {1, 0, 0}, {0, 1e6, 0}), 1e-6, 1e-15);
}

/// Four triangles of a unit square around a centre vertex at (0.5, c_y): c_y near 0 flattens
/// triangle 0 (the one on the bottom edge) into a cap.
TriMesh fan(double centre_y) {
  TriMesh mesh;
  mesh.vertices.resize(5, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, centre_y, 0;
  mesh.triangles.resize(4, 3);
  mesh.triangles << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4;
  return mesh;
}

TEST(TriangleShape, ShellsOfWellShapedTrianglesPass) {
  EXPECT_NO_THROW(check_shell_triangle_shapes(fan(0.5), "shell 'square'"));
  // Just above the floor: a cap of quality 2e-5 (height 2e-5 over base 1).
  EXPECT_NO_THROW(check_shell_triangle_shapes(fan(2e-5), "shell 'square'"));
}

TEST(TriangleShape, ASliverIsRefusedNamingTheShellTheTriangleAndWhatToDo) {
  try {
    check_shell_triangle_shapes(fan(1e-6), "scene.toml: shell 'square'");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("scene.toml: shell 'square': triangle 0 is a sliver"), std::string::npos)
        << message;
    EXPECT_NE(message.find("1e-06 × its longest edge, below 1e-05 (1 triangle(s)"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("Remesh the shell"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace psq
