// The scene library in jobs/scenes: every scene loads, its meshes build and every pin and load
// selects vertices, and each selects what its comments say.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "engine/mesh/mesh_io.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/scene/rigid_motion.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/scene/shell_mesh.hpp"
#include "engine/scene/vertex_selection.hpp"
#include "support/library_scene.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// One shell of an example scene, built, with the vertices of each pin and load.
struct BuiltShell {
  TriMesh mesh;
  MeshTopology topology;
  std::map<std::string, std::vector<int>> pins;
  std::vector<std::vector<int>> loads;
};

std::vector<BuiltShell> build(const Scene& scene) {
  std::vector<BuiltShell> out;
  for (const Shell& shell : scene.shells) {
    BuiltShell built;
    built.mesh = build_shell_mesh(shell.mesh);
    validate_mesh(built.mesh, shell.name);
    built.topology = MeshTopology::build(built.mesh, shell.name);
    for (const PinnedSet& pin : shell.pins)
      built.pins[pin.name] = select_vertices(pin.selector, built.mesh, built.topology, pin.name);
    for (const Load& load : shell.loads)
      built.loads.push_back(select_vertices(load.selector, built.mesh, built.topology, "load"));
    out.push_back(std::move(built));
  }
  return out;
}

TEST(ExampleScenes, EveryLibrarySceneLoadsAndSelectsVertices) {
  int scenes = 0;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(test::source_dir() / "jobs" / "scenes")) {
    if (entry.path().extension() != ".toml") continue;
    ++scenes;
    SCOPED_TRACE(entry.path().string());
    const Scene scene = read_scene(entry.path());
    ASSERT_FALSE(scene.shells.empty());
    const std::vector<BuiltShell> shells = build(scene);
    for (std::size_t s = 0; s < shells.size(); ++s) {
      EXPECT_GT(shells[s].mesh.triangle_count(), 0);
      EXPECT_EQ(shells[s].pins.size(), scene.shells[s].pins.size());  // pin names are unique
      for (const auto& [name, vertices] : shells[s].pins) EXPECT_FALSE(vertices.empty()) << name;
      for (const auto& vertices : shells[s].loads) EXPECT_FALSE(vertices.empty());
    }
  }
  EXPECT_GE(scenes, 4);
}

TEST(ExampleScenes, DrapeHangsAOneMetreClothByTwoCorners) {
  const Scene scene = test::library_scene("drape");
  EXPECT_EQ(scene.gravity, Eigen::Vector3d(0, 0, -9.81));
  ASSERT_EQ(scene.shells.size(), 1u);
  const Material& cloth = scene.shells[0].material;
  EXPECT_GE(cloth.youngs_modulus, 1e5);
  EXPECT_LE(cloth.youngs_modulus, 1e6);
  EXPECT_GE(cloth.density, 200);
  EXPECT_LE(cloth.density, 500);
  EXPECT_NEAR(cloth.thickness, 5e-4, 1e-12);
  const BuiltShell shell = build(scene)[0];
  ASSERT_EQ(shell.pins.size(), 2u);
  for (const auto& [name, vertices] : shell.pins) {
    ASSERT_EQ(vertices.size(), 1u) << name;
    const Eigen::Vector3d corner = shell.mesh.vertices.row(vertices[0]);
    EXPECT_NEAR(std::abs(corner.x()), 0.5, 1e-12) << name;
    EXPECT_NEAR(corner.y(), 0.5, 1e-12) << name;
  }
}

TEST(ExampleScenes, HangingSheetIsUprightLimitedAndPinnedAlongItsTopEdge) {
  const Scene scene = test::library_scene("hanging_sheet");
  ASSERT_EQ(scene.shells.size(), 1u);
  ASSERT_TRUE(scene.shells[0].strain_limit);
  EXPECT_EQ(scene.shells[0].strain_limit->limit, 1.05);
  const BuiltShell shell = build(scene)[0];
  EXPECT_LT(shell.mesh.vertices.col(1).cwiseAbs().maxCoeff(), 1e-12);  // in the xz plane
  const std::vector<int>& top = shell.pins.at("top");
  EXPECT_EQ(top.size(), 11u);  // the whole top row of the 2 cm grid
  for (int v : top) EXPECT_NEAR(shell.mesh.vertices(v, 2), 0.1, 1e-12);
}

TEST(ExampleScenes, TwistTurnsOneEndOfTheRibbonAThirdOfATurn) {
  const Scene scene = test::library_scene("twist");
  ASSERT_EQ(scene.shells.size(), 1u);
  const Shell& ribbon = scene.shells[0];
  const BuiltShell shell = build(scene)[0];
  const std::vector<int>& fixed = shell.pins.at("fixed_end");
  const std::vector<int>& turned = shell.pins.at("turned_end");
  EXPECT_GE(fixed.size(), 5u);
  EXPECT_GE(turned.size(), 5u);
  for (int v : fixed) EXPECT_NEAR(shell.mesh.vertices(v, 0), -0.2, 1e-12);
  for (int v : turned) EXPECT_NEAR(shell.mesh.vertices(v, 0), 0.2, 1e-12);

  ASSERT_EQ(ribbon.pins.size(), 2u);
  EXPECT_TRUE(ribbon.pins[0].motions.empty());
  const auto& motions = ribbon.pins[1].motions;
  const double end = scene.time.step * scene.time.frames;
  // 120° about the x axis maps (0.2, 0.05, 0) to (0.2, 0.05 cos 120°, 0.05 sin 120°), reached by
  // the last frame.
  const Eigen::Vector3d corner(0.2, 0.05, 0);
  EXPECT_LT((apply_motions(motions, corner, end) -
             Eigen::Vector3d(0.2, -0.025, 0.05 * std::sqrt(0.75)))
                .norm(),
            1e-12);
  // A quarter of the way through, a quarter of the turn (30°).
  const Eigen::Vector3d quarter(0.2, 0.05 * std::sqrt(0.75), 0.025);
  EXPECT_LT((apply_motions(motions, corner, 0.25 * end) - quarter).norm(), 1e-12);
}

TEST(ExampleScenes, CylinderCompressPinsBothRimsAndPushesTheTopDown) {
  const Scene scene = test::library_scene("cylinder_compress");
  ASSERT_EQ(scene.shells.size(), 1u);
  const Shell& can = scene.shells[0];
  EXPECT_EQ(can.mesh.kind, MeshSource::Kind::Cylinder);
  EXPECT_EQ(can.material.youngs_modulus, 69e9);
  const BuiltShell shell = build(scene)[0];
  // The two boxes select exactly the two boundary loops (the rims), nothing else.
  ASSERT_EQ(shell.topology.boundary_loops.size(), 2u);
  std::vector<std::vector<int>> rims;
  for (std::vector<int> loop : shell.topology.boundary_loops) {
    std::sort(loop.begin(), loop.end());
    rims.push_back(loop);
  }
  const std::vector<int>& bottom = shell.pins.at("bottom_rim");
  const std::vector<int>& top = shell.pins.at("top_rim");
  EXPECT_TRUE((bottom == rims[0] && top == rims[1]) || (bottom == rims[1] && top == rims[0]));
  for (int v : bottom) EXPECT_NEAR(shell.mesh.vertices(v, 2), 0.0, 1e-12);
  for (int v : top) EXPECT_NEAR(shell.mesh.vertices(v, 2), can.mesh.cylinder.height, 1e-12);
  // The top moves down by 0.5% of the height, just below the can's axial buckling strain.
  const Eigen::Vector3d rest(0.05, 0, 0.1);
  const double end = scene.time.step * scene.time.frames;
  const double drop = rest.z() - apply_motions(can.pins.at(1).motions, rest, end).z();
  EXPECT_NEAR(drop, 0.005 * can.mesh.cylinder.height, 1e-12);
}

TEST(ExampleScenes, CantileverClampsTwoColumnsAndLoadsTheTipLine) {
  const Scene scene = test::library_scene("cantilever");
  EXPECT_EQ(scene.gravity, Eigen::Vector3d::Zero());
  ASSERT_EQ(scene.shells.size(), 1u);
  const Shell& strip = scene.shells[0];
  ASSERT_TRUE(strip.mesh.sheet.structured);
  ASSERT_EQ(strip.loads.size(), 1u);
  EXPECT_EQ(strip.loads[0].kind, Load::Kind::Line);
  const BuiltShell shell = build(scene)[0];
  // 0.2 × 0.02 m at 5 mm: 40 × 4 squares, columns of 5 vertices 5 mm apart.
  ASSERT_EQ(shell.mesh.vertex_count(), 41 * 5);
  EXPECT_EQ(shell.pins.at("clamp").size(), 2u * 5u);
  ASSERT_EQ(shell.loads[0].size(), 5u);
  for (int v : shell.loads[0]) EXPECT_NEAR(shell.mesh.vertices(v, 0), 0.1, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Contact scenes (simulated at CI size in tests/sim/contact_scenes_test.cpp)

/// Lowest and highest z of a mesh.
std::pair<double, double> z_range(const TriMesh& mesh) {
  return {mesh.vertices.col(2).minCoeff(), mesh.vertices.col(2).maxCoeff()};
}

TEST(ExampleScenes, DrapeSphereHangsTheClothAboveAFixedBallWithFriction) {
  const Scene scene = test::library_scene("drape_sphere");
  EXPECT_DOUBLE_EQ(scene.contact.friction, 0.3);
  ASSERT_EQ(scene.colliders.size(), 1u);
  EXPECT_TRUE(scene.colliders[0].motions.empty());
  const TriMesh ball = build_shell_mesh(scene.colliders[0].mesh);
  const TriMesh cloth = build(scene)[0].mesh;
  // The ball's top lies 5 cm below the flat cloth, which covers it.
  EXPECT_NEAR(z_range(cloth).first - z_range(ball).second, 0.05, 1e-3);
  EXPECT_GT(cloth.vertices.col(0).maxCoeff(), ball.vertices.col(0).maxCoeff());
}

TEST(ExampleScenes, TwistWrapTurnsBothEndsInOppositeDirectionsWithSelfContact) {
  const Scene scene = test::library_scene("twist_wrap");
  EXPECT_TRUE(scene.contact.self_contact);
  ASSERT_EQ(scene.shells.size(), 1u);
  const Shell& sheet = scene.shells[0];
  EXPECT_DOUBLE_EQ(sheet.mesh.sheet.width, 1.0);
  EXPECT_DOUBLE_EQ(sheet.mesh.sheet.height, 1.0);
  ASSERT_EQ(sheet.pins.size(), 2u);
  const double end = scene.time.step * scene.time.frames;
  // A quarter of the way, the ends have turned ±90°: (x, 0.5, 0) goes to (x', 0, ±0.5).
  const Eigen::Vector3d left = apply_motions(sheet.pins[0].motions, {-0.5, 0.5, 0}, 0.25 * end);
  const Eigen::Vector3d right = apply_motions(sheet.pins[1].motions, {0.5, 0.5, 0}, 0.25 * end);
  EXPECT_NEAR(left.z(), 0.5, 1e-9);
  EXPECT_NEAR(right.z(), -0.5, 1e-9);
  // At the end, a full turn each, the ends are back in place, 5 cm further in.
  EXPECT_LT(
      (apply_motions(sheet.pins[0].motions, {-0.5, 0.5, 0}, end) - Eigen::Vector3d(-0.45, 0.5, 0))
          .norm(),
      1e-9);
}

TEST(ExampleScenes, CylinderCrushIsAThinAluminiumCanUnderADescendingPlate) {
  const Scene scene = test::library_scene("cylinder_crush");
  const Material& can = scene.shells[0].material;
  EXPECT_EQ(can.youngs_modulus, 69e9);
  EXPECT_EQ(can.poisson_ratio, 0.33);
  EXPECT_EQ(can.thickness, 1e-4);
  ASSERT_EQ(scene.colliders.size(), 1u);
  const TriMesh plate = build_shell_mesh(scene.colliders[0].mesh);
  const double top = z_range(build(scene)[0].mesh).second;
  EXPECT_GT(z_range(plate).first, top);  // the plate starts above the can
  const Eigen::Vector3d corner = plate.vertices.row(0);
  const double end = scene.time.step * scene.time.frames;
  EXPECT_LT(apply_motions(scene.colliders[0].motions, corner, end).z(), top - 0.02);
}

TEST(ExampleScenes, BunnyPressUsesTheVendoredBunnyAboveTheSheet) {
  const Scene scene = test::library_scene("bunny_press");
  ASSERT_EQ(scene.colliders.size(), 1u);
  EXPECT_EQ(scene.colliders[0].mesh.file, test::source_dir() / "jobs" / "data" / "bunny.obj");
  const TriMesh bunny = build_shell_mesh(scene.colliders[0].mesh);
  EXPECT_EQ(bunny.vertex_count(), 1839);
  EXPECT_EQ(bunny.triangle_count(), 3674);
  validate_mesh(bunny, "bunny");
  // Feet 1 cm above the flat sheet, about 0.3 m across.
  EXPECT_NEAR(z_range(bunny).first, 0.01, 1e-3);
  EXPECT_NEAR(bunny.vertices.col(0).maxCoeff() - bunny.vertices.col(0).minCoeff(), 0.3, 0.01);
  EXPECT_EQ(z_range(build(scene)[0].mesh).second, 0.0);
}

}  // namespace
}  // namespace psq
