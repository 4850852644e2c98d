// The hinge constant k = D/6 reproduces Kirchhoff–Love bending on a cylinder:
// docs/bending-calibration.md derives it; these tests check it on regular meshes.

#include <gtest/gtest.h>

#include <cmath>

#include "elastic/elastic_test_meshes.hpp"
#include "engine/elastic/bending.hpp"
#include "engine/elastic/lame.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"

namespace psq {
namespace {

struct Wrap {
  double width, height, edge_length, radius;
  bool along_x;  ///< wrap the x direction around the cylinder (axis ∥ y), else y (axis ∥ x)
};

/// Bending energy of a flat structured sheet (its own rest shape) wrapped isometrically onto
/// a cylinder, divided by the Kirchhoff–Love energy of that wrap, (D/2)·Area/R².
double energy_ratio(const Wrap& wrap) {
  SheetGenerator spec;
  spec.structured = true;
  spec.width = wrap.width;
  spec.height = wrap.height;
  spec.edge_length = wrap.edge_length;
  const TriMesh sheet = make_structured_sheet(spec);
  const Material material = test::test_material();
  const BendingEnergy energy(sheet, MeshTopology::build(sheet), material);

  Positions wrapped = sheet.vertices;
  for (int v = 0; v < sheet.vertex_count(); ++v)
    wrapped.row(v) =
        test::wrap_onto_cylinder(sheet.vertices.row(v).transpose(), wrap.radius, wrap.along_x)
            .transpose();
  const double kirchhoff =
      0.5 * bending_modulus(material) * wrap.width * wrap.height / (wrap.radius * wrap.radius);
  return energy.value(flat(wrapped)) / kirchhoff;
}

TEST(BendingCalibration, CylinderWrapMatchesKirchhoffLoveWithinFivePercent) {
  // Axis along either grid direction, nearly square cells (1.1/⌈26.4⌉ by 1/24 etc.), two radii.
  for (bool along_x : {true, false})
    for (double edge : {1.0 / 24, 1.0 / 48, 1.0 / 96})
      for (double radius : {0.3, 1.0}) {
        const double ratio = energy_ratio({1.0, 1.1, edge, radius, along_x});
        EXPECT_NEAR(ratio, 1.0, 0.05)
            << "edge " << edge << " radius " << radius << (along_x ? " around x" : " around y");
      }
}

TEST(BendingCalibration, TwistOnTheGridCostsTwoOverOneMinusNuTimesKirchhoffLove) {
  // z = τxy on the checkerboard grid: each cell's diagonal hinge folds by τa√2 (its two
  // triangles have the slopes (0, τa) and (τa, 0), or (0, 0) and (τa, τa)) and no axis hinge
  // folds, so W = k·6·(τa√2)² = 2Dτ²a² per cell with k = D/6: 2Dτ² per area against
  // Kirchhoff–Love's D(1 − ν)τ². The curvature each hinge sees is right (the diagonals turn by
  // the twist); the constant calibrated on cylinders puts it on too few edges. Curved shells'
  // saddle modes carry this excess (docs/verification.md).
  SheetGenerator spec;
  spec.structured = true;
  spec.width = 1.0;
  spec.height = 1.0;
  spec.edge_length = 1.0 / 48;
  const TriMesh sheet = make_structured_sheet(spec);
  const double twist = 0.01;
  Positions twisted = sheet.vertices;
  for (int v = 0; v < sheet.vertex_count(); ++v)
    twisted(v, 2) = twist * sheet.vertices(v, 0) * sheet.vertices(v, 1);
  for (double nu : {0.0, 0.3}) {
    Material material = test::test_material();
    material.poisson_ratio = nu;
    const BendingEnergy energy(sheet, MeshTopology::build(sheet), material);
    const double kirchhoff = bending_modulus(material) * (1.0 - nu) * twist * twist;
    EXPECT_NEAR(energy.value(flat(twisted)) / kirchhoff / (2.0 / (1.0 - nu)), 1.0, 0.01)
        << "nu " << nu;
  }
}

TEST(BendingCalibration, CylinderWrapConvergesUnderRefinement) {
  // The only discrepancy on these meshes is the missing hinges along the two boundary
  // generators (one column of cells out of n), so the error shrinks like 1/n.
  double previous_error = 1.0;
  for (int cells : {12, 24, 48, 96}) {
    const double error = std::abs(1.0 - energy_ratio({1.0, 0.5, 1.0 / cells, 0.5, true}));
    EXPECT_NEAR(error, 1.0 / cells, 0.1 / cells) << cells << " cells";
    EXPECT_LT(error, previous_error);
    previous_error = error;
  }
}

}  // namespace
}  // namespace psq
