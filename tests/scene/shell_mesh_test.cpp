#include "engine/scene/shell_mesh.hpp"

#include <gtest/gtest.h>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

Positions points(std::initializer_list<Eigen::RowVector3d> rows) {
  Positions p(static_cast<Eigen::Index>(rows.size()), 3);
  int r = 0;
  for (const auto& row : rows) p.row(r++) = row;
  return p;
}

TEST(ApplyPlacement, ScalesThenRotatesThenTranslates) {
  MeshSource source;
  source.scale = 2.0;
  source.rotation_axis = {0, 0, 3};  // not unit: only the direction counts
  source.rotation_degrees = 90;
  source.translation = {1, 0, 0};
  Positions p = points({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  apply_placement(source, p);
  // (1,0,0) → ×2 → (2,0,0) → 90° about z → (0,2,0) → +(1,0,0) → (1,2,0); likewise the others.
  const Positions expected = points({{1, 2, 0}, {-1, 0, 0}, {1, 0, 2}});
  EXPECT_LT((p - expected).norm(), 1e-12) << p;
}

TEST(ApplyPlacement, RotationAboutAnObliqueAxis) {
  MeshSource source;
  source.rotation_axis = {1, 1, 1};
  source.rotation_degrees = 120;  // cycles the coordinate axes: x → y → z → x
  Positions p = points({{1, 0, 0}, {0, 1, 0}, {0.5, -2, 3}});
  apply_placement(source, p);
  const Positions expected = points({{0, 1, 0}, {0, 0, 1}, {3, 0.5, -2}});
  EXPECT_LT((p - expected).norm(), 1e-12) << p;
}

TEST(ApplyPlacement, RejectsNonPositiveScale) {
  MeshSource source;
  source.scale = 0;
  Positions p = points({{1, 0, 0}});
  EXPECT_THROW(apply_placement(source, p), InputError);
}

TEST(BuildShellMesh, PlacesAStructuredSheet) {
  MeshSource source;
  source.kind = MeshSource::Kind::Sheet;
  source.sheet.width = 0.4;
  source.sheet.height = 0.2;
  source.sheet.edge_length = 0.1;
  source.sheet.structured = true;
  source.rotation_axis = {1, 0, 0};
  source.rotation_degrees = 90;  // the sheet stands up in the x–z plane
  source.translation = {0, 0, 1};
  const TriMesh mesh = build_shell_mesh(source);
  ASSERT_EQ(mesh.vertex_count(), 5 * 3);
  const Eigen::RowVector3d lo = mesh.vertices.colwise().minCoeff();
  const Eigen::RowVector3d hi = mesh.vertices.colwise().maxCoeff();
  EXPECT_LT((lo - Eigen::RowVector3d(-0.2, 0, 0.9)).norm(), 1e-12) << lo;
  EXPECT_LT((hi - Eigen::RowVector3d(0.2, 0, 1.1)).norm(), 1e-12) << hi;
}

TEST(BuildShellMesh, ReadsAFileThenPlacesIt) {
  const auto dir = test::fresh_temp_dir("shell_mesh");
  const auto file = test::write_file(dir / "square.obj",
                                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  MeshSource source;
  source.kind = MeshSource::Kind::File;
  source.file = file;
  source.scale = 0.5;
  source.translation = {0, 0, 2};
  const TriMesh mesh = build_shell_mesh(source);
  ASSERT_EQ(mesh.vertex_count(), 4);
  ASSERT_EQ(mesh.triangle_count(), 2);
  EXPECT_LT((mesh.vertices.row(2) - Eigen::RowVector3d(0.5, 0.5, 2)).norm(), 1e-12);
}

}  // namespace
}  // namespace psq
