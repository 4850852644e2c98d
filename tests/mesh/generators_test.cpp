#include "engine/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io.hpp"
#include "engine/mesh/topology.hpp"

namespace psq {
namespace {

using Eigen::Vector3d;

Vector3d corner(const TriMesh& m, int f, int k) { return m.vertices.row(m.triangles(f, k)); }

/// (b − a) × (c − a): twice the area along the right-hand normal.
Vector3d area_vector(const TriMesh& m, int f) {
  return (corner(m, f, 1) - corner(m, f, 0)).cross(corner(m, f, 2) - corner(m, f, 0));
}

Vector3d centroid(const TriMesh& m, int f) {
  return (corner(m, f, 0) + corner(m, f, 1) + corner(m, f, 2)) / 3;
}

double total_area(const TriMesh& m) {
  double area = 0;
  for (int f = 0; f < m.triangle_count(); ++f) area += 0.5 * area_vector(m, f).norm();
  return area;
}

std::vector<double> edge_lengths(const TriMesh& m, const MeshTopology& t) {
  std::vector<double> lengths;
  for (const auto& [a, b] : t.edges)
    lengths.push_back((m.vertices.row(a) - m.vertices.row(b)).norm());
  return lengths;
}

double mean(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

double min_angle_degrees(const TriMesh& m) {
  double smallest = 180;
  for (int f = 0; f < m.triangle_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Vector3d u = corner(m, f, (k + 1) % 3) - corner(m, f, k);
      const Vector3d v = corner(m, f, (k + 2) % 3) - corner(m, f, k);
      smallest =
          std::min(smallest, std::atan2(u.cross(v).norm(), u.dot(v)) * 180 / std::numbers::pi);
    }
  return smallest;
}

int euler_characteristic(const TriMesh& m, const MeshTopology& t) {
  return m.vertex_count() - static_cast<int>(t.edges.size()) + m.triangle_count();
}

void expect_mean_edge_near(const TriMesh& m, const MeshTopology& t, double target) {
  const double mean_edge = mean(edge_lengths(m, t));
  EXPECT_GT(mean_edge, 0.75 * target);
  EXPECT_LT(mean_edge, 1.25 * target);
}

bool contains_point_2d(const TriMesh& m, int f, double x, double y) {
  for (int k = 0; k < 3; ++k) {
    const Vector3d a = corner(m, f, k), b = corner(m, f, (k + 1) % 3);
    if ((b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x()) < 0) return false;
  }
  return true;
}

template <class F>
void expect_input_error(F&& make, const std::string& topic) {
  try {
    make();
    ADD_FAILURE() << "expected InputError about " << topic;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(topic), std::string::npos) << e.what();
  }
}

// ---- sheets ----------------------------------------------------------------------------------

// (Designated initializers that skip `holes` trip -Wmissing-field-initializers in GCC 12.)
SheetGenerator sheet(double width, double height, double edge_length,
                     std::vector<SheetGenerator::Hole> holes = {}) {
  SheetGenerator spec;
  spec.width = width;
  spec.height = height;
  spec.edge_length = edge_length;
  spec.holes = std::move(holes);
  return spec;
}

TEST(Generators, DelaunaySheetCoversTheRectangleWithGoodTriangles) {
  const SheetGenerator spec = sheet(1.0, 0.8, 0.05);
  const TriMesh m = make_sheet(spec);
  EXPECT_NO_THROW(validate_mesh(m, "sheet"));
  const MeshTopology t = MeshTopology::build(m);
  expect_mean_edge_near(m, t, spec.edge_length);
  EXPECT_GT(min_angle_degrees(m), 20.0);
  EXPECT_NEAR(total_area(m), spec.width * spec.height, 1e-9);
  EXPECT_EQ(euler_characteristic(m, t), 1);
  ASSERT_EQ(t.boundary_loops.size(), 1u);
  for (int f = 0; f < m.triangle_count(); ++f) EXPECT_GT(area_vector(m, f).z(), 0) << f;
  EXPECT_TRUE(m.vertices.col(2).isZero(0));
  EXPECT_NEAR(m.vertices.col(0).minCoeff(), -0.5, 1e-12);
  EXPECT_NEAR(m.vertices.col(1).maxCoeff(), 0.4, 1e-12);
  // The boundary is resolved at the target size: 3.6 m of perimeter in pieces of ≤ 0.05 m.
  const auto& loop = t.boundary_loops[0];
  EXPECT_GE(loop.size(), 72u);
  for (std::size_t i = 0; i < loop.size(); ++i)
    EXPECT_LE((m.vertices.row(loop[i]) - m.vertices.row(loop[(i + 1) % loop.size()])).norm(),
              spec.edge_length + 1e-12);
}

TEST(Generators, DelaunaySheetHasItsHoles) {
  const SheetGenerator spec = sheet(1.0, 1.0, 0.03, {{-0.2, -0.2, 0.15}, {0.25, 0.2, 0.1}});
  const TriMesh m = make_sheet(spec);
  EXPECT_NO_THROW(validate_mesh(m, "holed sheet"));
  const MeshTopology t = MeshTopology::build(m);
  EXPECT_EQ(t.boundary_loops.size(), 1u + spec.holes.size());
  EXPECT_EQ(euler_characteristic(m, t), 1 - static_cast<int>(spec.holes.size()));
  expect_mean_edge_near(m, t, spec.edge_length);
  EXPECT_GT(min_angle_degrees(m), 20.0);
  double expected_area = spec.width * spec.height;
  for (const auto& hole : spec.holes) expected_area -= std::numbers::pi * hole.radius * hole.radius;
  EXPECT_NEAR(total_area(m) / expected_area, 1.0, 0.02);
  for (const auto& hole : spec.holes)
    for (int f = 0; f < m.triangle_count(); ++f)
      EXPECT_FALSE(contains_point_2d(m, f, hole.center_x, hole.center_y)) << f;
  // Every boundary vertex lies on the outer rectangle or close to one of the circles.
  for (const auto& loop : t.boundary_loops)
    for (int v : loop) {
      const double x = m.vertices(v, 0), y = m.vertices(v, 1);
      bool on_boundary = std::abs(std::abs(x) - 0.5) < 1e-12 || std::abs(std::abs(y) - 0.5) < 1e-12;
      for (const auto& hole : spec.holes)
        on_boundary |=
            std::abs(std::hypot(x - hole.center_x, y - hole.center_y) / hole.radius - 1) < 0.02;
      EXPECT_TRUE(on_boundary) << x << ", " << y;
    }
}

TEST(Generators, StructuredFlagGivesTheGrid) {
  SheetGenerator spec = sheet(1.0, 0.5, 0.1);
  spec.structured = true;
  const TriMesh m = make_sheet(spec);
  EXPECT_EQ(m.vertex_count(), 11 * 6);
  EXPECT_EQ(m.triangle_count(), 2 * 10 * 5);
}

TEST(Generators, SheetParametersAreChecked) {
  expect_input_error([] { make_sheet(sheet(0.0, 1.0, 0.1)); }, "width");
  expect_input_error([] { make_sheet(sheet(1.0, -1.0, 0.1)); }, "height");
  expect_input_error([] { make_sheet(sheet(1.0, 1.0, std::nan(""))); }, "edge_length");
  expect_input_error([] { make_sheet(sheet(1.0, 0.5, 0.6)); }, "edge_length");
  expect_input_error([] { make_sheet(sheet(1.0, 1.0, 0.1, {{0.45, 0.0, 0.1}})); }, "holes[0]");
  expect_input_error(
      [] {
        make_sheet(sheet(1.0, 1.0, 0.1, {{0.0, 0.0, 0.1}, {0.3, 0.0, -0.1}}));
      },
      "holes[1].radius");
  expect_input_error(
      [] {
        make_sheet(sheet(1.0, 1.0, 0.1, {{-0.1, 0.0, 0.15}, {0.1, 0.0, 0.15}}));
      },
      "overlap");
}

// ---- cylinders -------------------------------------------------------------------------------

TEST(Generators, CylinderHasNearEquilateralOutwardTriangles) {
  const CylinderGenerator spec{.radius = 0.5, .height = 1.0, .edge_length = 0.05};
  const TriMesh m = make_cylinder(spec);
  EXPECT_NO_THROW(validate_mesh(m, "cylinder"));
  const MeshTopology t = MeshTopology::build(m);
  for (double length : edge_lengths(m, t)) {
    EXPECT_GT(length, 0.8 * spec.edge_length);
    EXPECT_LT(length, 1.2 * spec.edge_length);
  }
  for (int f = 0; f < m.triangle_count(); ++f) {
    const Vector3d c = centroid(m, f);
    EXPECT_GT(area_vector(m, f).dot(Vector3d(c.x(), c.y(), 0)), 0) << f;
  }
  EXPECT_NEAR(total_area(m) / (2 * std::numbers::pi * spec.radius * spec.height), 1.0, 0.02);
  EXPECT_EQ(euler_characteristic(m, t), 0);
  ASSERT_EQ(t.boundary_loops.size(), 2u);
  // Rings: the same number of vertices at each height, round(2πr/edge) of them, all on the
  // radius, spanning z = 0 to z = height.
  std::map<double, int> ring_sizes;
  for (int v = 0; v < m.vertex_count(); ++v) {
    ++ring_sizes[m.vertices(v, 2)];
    EXPECT_NEAR(std::hypot(m.vertices(v, 0), m.vertices(v, 1)), spec.radius, 1e-12);
  }
  EXPECT_EQ(ring_sizes.begin()->first, 0.0);
  EXPECT_NEAR(ring_sizes.rbegin()->first, spec.height, 1e-12);
  for (const auto& [z, size] : ring_sizes) EXPECT_EQ(size, 63) << z;
  for (const auto& loop : t.boundary_loops) EXPECT_EQ(loop.size(), 63u);
}

TEST(Generators, CylinderParametersAreChecked) {
  expect_input_error([] { make_cylinder({.radius = -0.5}); }, "radius");
  expect_input_error([] { make_cylinder({.height = std::numeric_limits<double>::infinity()}); },
                     "height");
  expect_input_error([] { make_cylinder({.radius = 1.0, .height = 0.1, .edge_length = 0.2}); },
                     "edge_length");
  expect_input_error([] { make_cylinder({.radius = 0.1, .height = 5.0, .edge_length = 0.3}); },
                     "edge_length");
}

// ---- panels ----------------------------------------------------------------------------------

/// Every face's right-hand normal points away from `center_of(centroid)`.
template <class Center>
void expect_outward(const TriMesh& m, Center&& center_of) {
  for (int f = 0; f < m.triangle_count(); ++f) {
    const Vector3d c = centroid(m, f);
    EXPECT_GT(area_vector(m, f).dot(c - center_of(c)), 0) << "face " << f;
  }
}

TEST(Generators, CylindricalPanelIsAnEvenGridOnTheArc) {
  // Scordelis–Lo's roof: 80° of R = 25 (arc 34.9) by 50, edge 5: 7 → 8 by 10 cells.
  const CylindricalPanelGenerator spec{
      .radius = 25, .height = 50, .angle_degrees = 80, .edge_length = 5};
  const TriMesh m = make_cylindrical_panel(spec);
  EXPECT_NO_THROW(validate_mesh(m, "panel"));
  EXPECT_EQ(m.vertex_count(), 9 * 11);
  EXPECT_EQ(m.triangle_count(), 2 * 8 * 10);
  const MeshTopology t = MeshTopology::build(m);
  EXPECT_EQ(euler_characteristic(m, t), 1);
  expect_outward(m, [](const Vector3d& c) { return Vector3d(0, 0, c.z()); });
  double largest_angle = 0.0;
  for (int v = 0; v < m.vertex_count(); ++v) {
    EXPECT_NEAR(std::hypot(m.vertices(v, 0), m.vertices(v, 1)), 25, 1e-12);
    largest_angle = std::max(largest_angle, std::atan2(m.vertices(v, 1), m.vertices(v, 0)));
  }
  EXPECT_NEAR(largest_angle, 40 * std::numbers::pi / 180, 1e-12);  // centred on +x
}

TEST(Generators, ClosedCylindricalPanelHasNoSeamAndQuarterTurnVertices) {
  const TriMesh m = make_cylindrical_panel(
      {.radius = 1, .height = 1, .angle_degrees = 360, .edge_length = 0.3});
  EXPECT_NO_THROW(validate_mesh(m, "ring"));
  const MeshTopology t = MeshTopology::build(m);
  EXPECT_EQ(euler_characteristic(m, t), 0);
  ASSERT_EQ(t.boundary_loops.size(), 2u);
  EXPECT_EQ(t.boundary_loops[0].size(), 24u);  // 2π/0.3 = 20.9 → 24, a multiple of 4
  expect_outward(m, [](const Vector3d& c) { return Vector3d(0, 0, c.z()); });
  for (const Vector3d& p : {Vector3d(1, 0, 0.5), Vector3d(0, 1, 0.5), Vector3d(-1, 0, 0.5)}) {
    bool found = false;
    for (int v = 0; v < m.vertex_count(); ++v)
      found = found || (m.vertices.row(v).transpose() - p).norm() < 1e-12;
    EXPECT_TRUE(found) << p.transpose();
  }
}

TEST(Generators, SphericalPanelIsAClosedZoneWithAHole) {
  // The pinched hemisphere: R = 10, polar angles 18°..90°, edge 2: a meridian of 12.6 gives
  // 6.3 → 8 rows, the equator of 62.8 gives 31.4 → 32 columns.
  const TriMesh m = make_spherical_panel(
      {.radius = 10, .polar_min_degrees = 18, .polar_max_degrees = 90, .edge_length = 2});
  EXPECT_NO_THROW(validate_mesh(m, "hemisphere"));
  EXPECT_EQ(m.vertex_count(), 32 * 9);
  const MeshTopology t = MeshTopology::build(m);
  EXPECT_EQ(euler_characteristic(m, t), 0);
  ASSERT_EQ(t.boundary_loops.size(), 2u);
  expect_outward(m, [](const Vector3d&) { return Vector3d::Zero(); });
  double lowest = 1e9, highest = -1e9;
  for (int v = 0; v < m.vertex_count(); ++v) {
    EXPECT_NEAR(m.vertices.row(v).norm(), 10, 1e-12);
    lowest = std::min(lowest, m.vertices(v, 2));
    highest = std::max(highest, m.vertices(v, 2));
  }
  EXPECT_NEAR(lowest, 0, 1e-12);
  EXPECT_NEAR(highest, 10 * std::cos(18 * std::numbers::pi / 180), 1e-12);
}

TEST(Generators, PanelParametersAreChecked) {
  expect_input_error([] { make_cylindrical_panel({.radius = -1}); }, "radius");
  expect_input_error([] { make_cylindrical_panel({.angle_degrees = 400}); }, "angle_degrees");
  expect_input_error([] { make_cylindrical_panel({.height = 0.1, .edge_length = 0.2}); },
                     "edge_length");
  expect_input_error([] { make_spherical_panel({.polar_min_degrees = 0}); }, "polar_min_degrees");
  expect_input_error(
      [] { make_spherical_panel({.polar_min_degrees = 50, .polar_max_degrees = 40}); },
      "polar_max_degrees");
  expect_input_error([] { make_spherical_panel({.azimuth_degrees = 0}); }, "azimuth_degrees");
}

// ---- spheres ---------------------------------------------------------------------------------

TEST(Generators, GeodesicSphereIsClosedOutwardAndOnTheRadius) {
  const SphereGenerator spec{.radius = 1.0, .edge_length = 0.1};
  const TriMesh m = make_sphere(spec);
  EXPECT_NO_THROW(validate_mesh(m, "sphere"));
  const MeshTopology t = MeshTopology::build(m);
  for (int v = 0; v < m.vertex_count(); ++v)
    EXPECT_NEAR(m.vertices.row(v).norm(), spec.radius, 1e-12);
  for (int f = 0; f < m.triangle_count(); ++f)
    EXPECT_GT(area_vector(m, f).dot(centroid(m, f)), 0) << f;
  expect_mean_edge_near(m, t, spec.edge_length);
  EXPECT_NEAR(total_area(m) / (4 * std::numbers::pi * spec.radius * spec.radius), 1.0, 0.02);
  EXPECT_EQ(euler_characteristic(m, t), 2);
  EXPECT_TRUE(t.boundary_loops.empty());
  // A frequency-k geodesic sphere has 20k² triangles and 10k² + 2 vertices.
  const int k = static_cast<int>(std::lround(std::sqrt(m.triangle_count() / 20.0)));
  EXPECT_EQ(m.triangle_count(), 20 * k * k);
  EXPECT_EQ(m.vertex_count(), 10 * k * k + 2);
  // Merged: no two vertices closer than half the target edge.
  double closest = std::numeric_limits<double>::infinity();
  for (int a = 0; a < m.vertex_count(); ++a)
    for (int b = a + 1; b < m.vertex_count(); ++b)
      closest = std::min(closest, (m.vertices.row(a) - m.vertices.row(b)).squaredNorm());
  EXPECT_GT(std::sqrt(closest), 0.5 * spec.edge_length);
}

TEST(Generators, CoarsestSphereIsTheIcosahedron) {
  const TriMesh m = make_sphere({.radius = 2.0, .edge_length = 3.0});
  EXPECT_EQ(m.vertex_count(), 12);
  EXPECT_EQ(m.triangle_count(), 20);
  EXPECT_NO_THROW(validate_mesh(m, "icosahedron"));
}

TEST(Generators, SphereParametersAreChecked) {
  expect_input_error([] { make_sphere({.radius = 0.0}); }, "radius");
  expect_input_error([] { make_sphere({.edge_length = -0.1}); }, "edge_length");
  expect_input_error([] { make_sphere({.radius = 0.5, .edge_length = 1.0}); }, "edge_length");
}

}  // namespace
}  // namespace psq
