#include <gtest/gtest.h>

#include <limits>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io.hpp"

namespace psq {
namespace {

// Two triangles sharing the diagonal of a square of side `size`.
TriMesh square(double size = 1.0) {
  TriMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.vertices *= size;
  m.triangles.resize(2, 3);
  m.triangles << 0, 1, 2, 0, 2, 3;
  return m;
}

// Expects validate_mesh to throw InputError naming `source` and mentioning `topic`.
void expect_invalid(const TriMesh& mesh, const std::string& topic) {
  try {
    validate_mesh(mesh, "scene shell 'cloth'");
    ADD_FAILURE() << "expected InputError about " << topic;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("scene shell 'cloth'"), std::string::npos) << message;
    EXPECT_NE(message.find(topic), std::string::npos) << message;
  }
}

TEST(MeshValidation, AcceptsValidMeshesAtAnyScale) {
  // The degeneracy threshold is relative: a micrometre square is as valid as a kilometre one.
  EXPECT_NO_THROW(validate_mesh(square(), "unit"));
  EXPECT_NO_THROW(validate_mesh(square(1e-6), "tiny"));
  EXPECT_NO_THROW(validate_mesh(square(1e3), "huge"));
}

TEST(MeshValidation, AcceptsUnreferencedVertices) {
  TriMesh m = square();
  m.vertices.conservativeResize(5, 3);
  m.vertices.row(4) << 7, 7, 7;
  EXPECT_NO_THROW(validate_mesh(m, "loose vertex"));
}

TEST(MeshValidation, RejectsEmptyMeshes) {
  TriMesh no_triangles = square();
  no_triangles.triangles.resize(0, 3);
  expect_invalid(no_triangles, "empty");
  expect_invalid(TriMesh{}, "empty");
}

TEST(MeshValidation, RejectsNonFiniteCoordinates) {
  TriMesh m = square();
  m.vertices(2, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_invalid(m, "vertex 2 has a non-finite");
  m.vertices(2, 1) = std::numeric_limits<double>::infinity();
  expect_invalid(m, "vertex 2 has a non-finite");
}

TEST(MeshValidation, RejectsBadIndices) {
  TriMesh m = square();
  m.triangles(1, 2) = 4;
  expect_invalid(m, "triangle 1 refers to vertex 4");
  m.triangles(1, 2) = -1;
  expect_invalid(m, "triangle 1 refers to vertex -1");
  m.triangles.row(1) << 2, 0, 2;
  expect_invalid(m, "triangle 1 repeats vertex 2");
}

TEST(MeshValidation, RejectsDegenerateTriangles) {
  TriMesh m = square();
  m.vertices.row(2) << 2, 0, 0;  // triangle 0 = (0,0), (1,0), (2,0): collinear
  expect_invalid(m, "triangle 0 is degenerate");
  // Vertex 3 a hair off the diagonal of triangle 1: area ≈ 5e-16 against diagonal² = 2.
  TriMesh sliver = square();
  sliver.vertices.row(3) << 0.5, 0.5 + 1e-15, 0;
  expect_invalid(sliver, "triangle 1 is degenerate");
}

TEST(MeshValidation, RejectsNonManifoldAndMisorientedConnectivity) {
  TriMesh fin = square();
  fin.vertices.conservativeResize(5, 3);
  fin.vertices.row(4) << 0.5, 0.5, 1;
  fin.triangles.conservativeResize(3, 3);
  fin.triangles.row(2) << 2, 0, 4;
  expect_invalid(fin, "non-manifold");
  TriMesh flipped = square();
  flipped.triangles.row(1) << 0, 3, 2;
  expect_invalid(flipped, "orient");
}

}  // namespace
}  // namespace psq
