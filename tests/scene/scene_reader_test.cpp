#include "engine/scene/scene_reader.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <tuple>

#include "engine/core/error.hpp"
#include "support/scene_error.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

void expect_vector(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected) {
  EXPECT_EQ(actual, expected) << actual.transpose() << " vs " << expected.transpose();
}

// Every key of the format, each with a value different from its default.
constexpr const char* kFullScene = R"(name = "everything"
gravity = [0.5, -1, -9.5]

[time]
step = 0.02
frames = 7

[solver]
tolerance = 2.5e-5
max_iterations = 33

[[shell]]
name = "plate"
mesh = { generator = "sheet", width = 2, height = 1.5, edge_length = 0.05, structured = false, holes = [{ center = [0.25, -0.125], radius = 0.1 }, { center = [-0.5, 0.25], radius = 0.2 }] }
placement = { scale = 1.5, rotation_axis = [0, 1, 0], rotation_degrees = 30, translation = [1, 2, 3] }
material = { youngs_modulus = 2.5e6, poisson_ratio = 0.25, density = 450, thickness = 7.5e-4 }

[[shell.pin]]
name = "edge"
box = { min = [-1.01, -1, -0.5], max = [-0.99, 1, 0.5] }

[[shell.pin.motion]]
start = 0.5
end = 1.25
translation = [0, 0, 0.1]
axis_point = [1, 2, 3]
axis = [0, 1, 0]
angle_degrees = -45

[[shell.pin.motion]]
start = 1.25
end = 2
translation = [0.3, 0, 0]

[[shell.pin]]
name = "rim"
boundary_loop = 1
components = ["z", "x"]

[[shell.load]]
kind = "line"
boundary_loop = 0
force = [0, 0, -2.5]

[[shell]]
name = "tube"

[shell.mesh]
generator = "cylinder"
radius = 0.25
height = 0.75
edge_length = 0.04

[shell.material]
youngs_modulus = 69e9
poisson_ratio = 0.33
density = 2700
thickness = 5e-4

[[shell.load]]
vertices = [3, 1, 4]
force = [1, 0, 0]

[[shell]]
name = "ball"
mesh = { generator = "sphere", radius = 0.3, edge_length = 0.03 }
material = { youngs_modulus = 1e5, poisson_ratio = -0.5, density = 100, thickness = 2e-3 }
bending = "midedge"

[[shell]]
name = "imported"
mesh = { file = "meshes/square.obj" }
material = { youngs_modulus = 1e6, poisson_ratio = 0, density = 1000, thickness = 1e-3 }

[[shell.pin]]
name = "listed"
vertices = [0, 2]
)";

TEST(ReadScene, ReadsEveryFieldAsWritten) {
  const fs::path dir = test::fresh_temp_dir("read_scene_full");
  fs::create_directories(dir / "meshes");
  test::write_file(dir / "meshes" / "square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  const fs::path path = test::write_file(dir / "full.toml", kFullScene);
  const Scene scene = read_scene(path);

  EXPECT_EQ(scene.source, path);
  EXPECT_EQ(scene.name, "everything");
  expect_vector(scene.gravity, {0.5, -1, -9.5});
  EXPECT_EQ(scene.time.step, 0.02);
  EXPECT_EQ(scene.time.frames, 7);
  ASSERT_TRUE(scene.solver.tolerance);
  EXPECT_EQ(*scene.solver.tolerance, 2.5e-5);
  EXPECT_EQ(scene.solver.max_iterations, 33);
  ASSERT_EQ(scene.shells.size(), 4u);

  const Shell& plate = scene.shells[0];
  EXPECT_EQ(plate.name, "plate");
  EXPECT_EQ(plate.mesh.kind, MeshSource::Kind::Sheet);
  EXPECT_EQ(plate.mesh.sheet.width, 2);
  EXPECT_EQ(plate.mesh.sheet.height, 1.5);
  EXPECT_EQ(plate.mesh.sheet.edge_length, 0.05);
  EXPECT_FALSE(plate.mesh.sheet.structured);
  ASSERT_EQ(plate.mesh.sheet.holes.size(), 2u);
  EXPECT_EQ(plate.mesh.sheet.holes[0].center_x, 0.25);
  EXPECT_EQ(plate.mesh.sheet.holes[0].center_y, -0.125);
  EXPECT_EQ(plate.mesh.sheet.holes[0].radius, 0.1);
  EXPECT_EQ(plate.mesh.sheet.holes[1].center_x, -0.5);
  EXPECT_EQ(plate.mesh.sheet.holes[1].center_y, 0.25);
  EXPECT_EQ(plate.mesh.sheet.holes[1].radius, 0.2);
  EXPECT_EQ(plate.mesh.scale, 1.5);
  expect_vector(plate.mesh.rotation_axis, {0, 1, 0});
  EXPECT_EQ(plate.mesh.rotation_degrees, 30);
  expect_vector(plate.mesh.translation, {1, 2, 3});
  EXPECT_EQ(plate.material.youngs_modulus, 2.5e6);
  EXPECT_EQ(plate.material.poisson_ratio, 0.25);
  EXPECT_EQ(plate.material.density, 450);
  EXPECT_EQ(plate.material.thickness, 7.5e-4);
  EXPECT_EQ(plate.bending, BendingModel::hinge);

  ASSERT_EQ(plate.pins.size(), 2u);
  const PinnedSet& edge = plate.pins[0];
  EXPECT_EQ(edge.name, "edge");
  EXPECT_EQ(edge.selector.kind, VertexSelector::Kind::Box);
  expect_vector(edge.selector.box_min, {-1.01, -1, -0.5});
  expect_vector(edge.selector.box_max, {-0.99, 1, 0.5});
  EXPECT_EQ(edge.selector.source_file, path);
  EXPECT_EQ(edge.selector.source_line, 20);
  ASSERT_EQ(edge.motions.size(), 2u);
  EXPECT_EQ(edge.motions[0].start_time, 0.5);
  EXPECT_EQ(edge.motions[0].end_time, 1.25);
  expect_vector(edge.motions[0].translation, {0, 0, 0.1});
  expect_vector(edge.motions[0].axis_point, {1, 2, 3});
  expect_vector(edge.motions[0].axis_direction, {0, 1, 0});
  EXPECT_EQ(edge.motions[0].angle_degrees, -45);
  EXPECT_EQ(edge.motions[1].start_time, 1.25);
  EXPECT_EQ(edge.motions[1].end_time, 2);
  expect_vector(edge.motions[1].translation, {0.3, 0, 0});
  expect_vector(edge.motions[1].axis_point, {0, 0, 0});      // default
  expect_vector(edge.motions[1].axis_direction, {0, 0, 1});  // default
  EXPECT_EQ(edge.motions[1].angle_degrees, 0);               // default
  const PinnedSet& rim = plate.pins[1];
  EXPECT_EQ(rim.name, "rim");
  EXPECT_EQ(rim.selector.kind, VertexSelector::Kind::BoundaryLoop);
  EXPECT_EQ(rim.selector.boundary_loop, 1);
  EXPECT_TRUE(rim.motions.empty());
  EXPECT_EQ(edge.components, (PinComponents{true, true, true}));  // default: all three
  EXPECT_EQ(rim.components, (PinComponents{true, false, true}));
  ASSERT_EQ(plate.loads.size(), 1u);
  EXPECT_EQ(plate.loads[0].kind, Load::Kind::Line);
  EXPECT_EQ(plate.loads[0].selector.kind, VertexSelector::Kind::BoundaryLoop);
  EXPECT_EQ(plate.loads[0].selector.boundary_loop, 0);
  expect_vector(plate.loads[0].total_force, {0, 0, -2.5});

  const Shell& tube = scene.shells[1];
  EXPECT_EQ(tube.name, "tube");
  EXPECT_EQ(tube.mesh.kind, MeshSource::Kind::Cylinder);
  EXPECT_EQ(tube.mesh.cylinder.radius, 0.25);
  EXPECT_EQ(tube.mesh.cylinder.height, 0.75);
  EXPECT_EQ(tube.mesh.cylinder.edge_length, 0.04);
  EXPECT_EQ(tube.mesh.scale, 1.0);  // no placement: identity
  EXPECT_EQ(tube.mesh.rotation_degrees, 0);
  expect_vector(tube.mesh.translation, {0, 0, 0});
  EXPECT_EQ(tube.material.youngs_modulus, 69e9);
  EXPECT_EQ(tube.material.poisson_ratio, 0.33);
  EXPECT_EQ(tube.material.density, 2700);
  EXPECT_EQ(tube.material.thickness, 5e-4);
  EXPECT_TRUE(tube.pins.empty());
  ASSERT_EQ(tube.loads.size(), 1u);
  EXPECT_EQ(tube.loads[0].kind, Load::Kind::Point);  // default kind
  EXPECT_EQ(tube.loads[0].selector.kind, VertexSelector::Kind::List);
  EXPECT_EQ(tube.loads[0].selector.indices, (std::vector<int>{3, 1, 4}));
  expect_vector(tube.loads[0].total_force, {1, 0, 0});

  const Shell& ball = scene.shells[2];
  EXPECT_EQ(ball.mesh.kind, MeshSource::Kind::Sphere);
  EXPECT_EQ(ball.mesh.sphere.radius, 0.3);
  EXPECT_EQ(ball.mesh.sphere.edge_length, 0.03);
  EXPECT_EQ(ball.material.poisson_ratio, -0.5);
  EXPECT_EQ(ball.material.thickness, 2e-3);
  EXPECT_EQ(ball.bending, BendingModel::midedge);

  const Shell& imported = scene.shells[3];
  EXPECT_EQ(imported.mesh.kind, MeshSource::Kind::File);
  EXPECT_TRUE(fs::equivalent(imported.mesh.file, dir / "meshes" / "square.obj"));
  ASSERT_EQ(imported.pins.size(), 1u);
  EXPECT_EQ(imported.pins[0].selector.indices, (std::vector<int>{0, 2}));
}

TEST(ReadScene, AppliesTheDefaultsOfTheSceneModel) {
  const fs::path dir = test::fresh_temp_dir("read_scene_defaults");
  const fs::path path = test::write_file(dir / "minimal.toml", R"(
[[shell]]
name = "s"
mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3 }
)");
  const Scene scene = read_scene(path);
  const Scene defaults;
  EXPECT_EQ(scene.name, "minimal");  // the file's stem
  expect_vector(scene.gravity, defaults.gravity);
  EXPECT_EQ(scene.time.step, defaults.time.step);
  EXPECT_EQ(scene.time.frames, defaults.time.frames);
  EXPECT_FALSE(scene.solver.tolerance);
  EXPECT_EQ(scene.solver.max_iterations, defaults.solver.max_iterations);
  ASSERT_EQ(scene.shells.size(), 1u);
  EXPECT_FALSE(scene.shells[0].mesh.sheet.structured);
  EXPECT_TRUE(scene.shells[0].mesh.sheet.holes.empty());
  EXPECT_EQ(scene.shells[0].bending, BendingModel::hinge);
  EXPECT_TRUE(scene.shells[0].pins.empty());
  EXPECT_TRUE(scene.shells[0].loads.empty());
  EXPECT_FALSE(scene.shells[0].strain_limit);
}

TEST(ReadScene, ReadsAStrainLimitWithAndWithoutItsStiffness) {
  const fs::path dir = test::fresh_temp_dir("read_scene_strain_limit");
  const fs::path path = test::write_file(dir / "limited.toml", R"([[shell]]
name = "given"
mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3, strain_limit = 1.1, strain_limit_stiffness = 2.5 }

[[shell]]
name = "automatic"
mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3, strain_limit = 1.02 }
)");
  const Scene scene = read_scene(path);
  ASSERT_EQ(scene.shells.size(), 2u);
  ASSERT_TRUE(scene.shells[0].strain_limit);
  EXPECT_EQ(scene.shells[0].strain_limit->limit, 1.1);
  EXPECT_EQ(scene.shells[0].strain_limit->stiffness, 2.5);
  ASSERT_TRUE(scene.shells[1].strain_limit);
  EXPECT_EQ(scene.shells[1].strain_limit->limit, 1.02);
  EXPECT_FALSE(scene.shells[1].strain_limit->stiffness);
}

TEST(ReadScene, EmptyListsOfTablesAreAllowed) {
  const fs::path dir = test::fresh_temp_dir("read_scene_empty_lists");
  const fs::path path = test::write_file(dir / "lists.toml", R"([[shell]]
name = "s"
mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1, holes = [] }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3 }
pin = []
load = []
)");
  const Scene scene = read_scene(path);
  ASSERT_EQ(scene.shells.size(), 1u);
  EXPECT_TRUE(scene.shells[0].mesh.sheet.holes.empty());
  EXPECT_TRUE(scene.shells[0].pins.empty());
  EXPECT_TRUE(scene.shells[0].loads.empty());
}

// ---------------------------------------------------------------------------------------------
// Bad input: each case edits one line of a valid scene and expects an InputError located at a
// given line that names a given key.

const std::vector<std::string> kValidLines = {
    /*  1 */ R"(name = "bad")",
    /*  2 */ R"([time])",
    /*  3 */ R"(step = 0.04)",
    /*  4 */ R"(frames = 25)",
    /*  5 */ R"([solver])",
    /*  6 */ R"(max_iterations = 200)",
    /*  7 */ R"([[shell]])",
    /*  8 */ R"(name = "sheet")",
    /*  9 */ R"(mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1 })",
    /* 10 */
    R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3 })",
    /* 11 */ R"([[shell.pin]])",
    /* 12 */ R"(name = "left")",
    /* 13 */ R"(box = { min = [-1, -1, -1], max = [-0.4, 1, 1] })",
    /* 14 */ R"([[shell.pin.motion]])",
    /* 15 */ R"(start = 0)",
    /* 16 */ R"(end = 1)",
    /* 17 */ R"(axis = [1, 0, 0])",
    /* 18 */ R"(angle_degrees = 90)",
    /* 19 */ R"([[shell.load]])",
    /* 20 */ R"(kind = "point")",
    /* 21 */ R"(vertices = [0, 5])",
    /* 22 */ R"(force = [0, 0, -1])",
};

struct BadCase {
  const char* name;
  int edited_line;                     ///< the line of kValidLines replaced by `text`
  const char* text;                    ///< may hold several lines, or none (the line is deleted)
  int error_line;                      ///< where the error must be reported
  std::vector<std::string> fragments;  ///< the message must contain each
};

std::string scene_with(int edited_line, const std::string& text) {
  std::string out;
  for (int line = 1; line <= static_cast<int>(kValidLines.size()); ++line) {
    const std::string& content = line == edited_line ? text : kValidLines[line - 1];
    if (line == edited_line && text.empty()) continue;
    out += content + "\n";
  }
  return out;
}

const std::vector<BadCase> kBadCases = {
    // clang-format off
    {"unknown_key_with_suggestion", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thicknes = 1e-3 })",
     10, {"unknown key 'thicknes' in [shell.material]", "did you mean 'thickness'?"}},
    {"unknown_top_level_key", 1,
     "gravty = [0, 0, -9.81]",
     1, {"unknown key 'gravty'", "did you mean 'gravity'?"}},
    {"unknown_key_without_suggestion", 15,
     "begin = 0",
     15, {"unknown key 'begin' in [shell.pin.motion]", "valid keys:", "'start'"}},
    {"key_of_another_generator", 9,
     R"(mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1, radius = 2 })",
     9, {"unknown key 'radius' in [shell.mesh]"}},
    {"unknown_generator", 9,
     R"(mesh = { generator = "sheat", width = 1, height = 1, edge_length = 0.1 })",
     9, {"generator 'sheat'", "did you mean 'sheet'?"}},
    {"unknown_load_kind", 20, R"(kind = "surface")", 20, {"kind 'surface'", "'point', 'line'"}},
    {"string_for_number", 9,
     R"(mesh = { generator = "sheet", width = "1", height = 1, edge_length = 0.1 })",
     9, {"expected a number for 'width'", "got a string"}},
    {"float_for_integer", 4, "frames = 2.5", 4, {"expected an integer for 'frames'"}},
    {"short_vector", 22, "force = [0, -1]", 22, {"expected an array of 3 numbers for 'force'"}},
    {"string_in_vector", 17, R"(axis = [1, 0, "z"])", 17, {"array of 3 numbers for 'axis'"}},
    {"nan_number", 3, "step = nan", 3, {"finite number for 'step'"}},
    {"boolean_type", 9,
     R"(mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1, structured = 1 })",
     9, {"true or false for 'structured'"}},
    {"table_expected", 10, "material = 5", 10, {"expected a table for 'material'"}},
    {"missing_required_key", 10,
     R"(material = { poisson_ratio = 0.3, density = 200, thickness = 1e-3 })",
     10, {"missing required key 'youngs_modulus' in [shell.material]"}},
    {"missing_material", 10, "", 7, {"missing required table 'material' in [shell]"}},
    {"missing_force", 22, "", 19, {"missing required key 'force' in [shell.load]"}},
    {"missing_pin_name", 12, "", 11, {"missing required key 'name' in [shell.pin]"}},
    {"zero_youngs_modulus", 10,
     R"(material = { youngs_modulus = 0, poisson_ratio = 0.3, density = 200, thickness = 1e-3 })",
     10, {"'youngs_modulus'", "must be positive"}},
    {"poisson_half", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.5, density = 200, thickness = 1e-3 })",
     10, {"'poisson_ratio'", "(-1, 0.5)"}},
    {"poisson_minus_one", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = -1, density = 200, thickness = 1e-3 })",
     10, {"'poisson_ratio'", "(-1, 0.5)"}},
    {"negative_density", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = -200, thickness = 1e-3 })",
     10, {"'density'", "positive"}},
    {"zero_thickness", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 0 })",
     10, {"'thickness'", "positive"}},
    {"strain_limit_not_above_one", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3, strain_limit = 1 })",
     10, {"'strain_limit' in [shell.material]", "greater than 1", "got 1"}},
    {"strain_limit_stiffness_alone", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3, strain_limit_stiffness = 2 })",
     10, {"'strain_limit_stiffness' in [shell.material]", "together with 'strain_limit'"}},
    {"zero_strain_limit_stiffness", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3, strain_limit = 1.1, strain_limit_stiffness = 0 })",
     10, {"'strain_limit_stiffness' in [shell.material]", "positive"}},
    {"misspelt_strain_limit", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3, strain_limt = 1.1 })",
     10, {"unknown key 'strain_limt' in [shell.material]", "did you mean 'strain_limit'?"}},
    {"zero_step", 3, "step = 0", 3, {"'step' in [time]", "positive"}},
    {"zero_frames", 4, "frames = 0", 4, {"'frames' in [time]", "at least 1"}},
    {"zero_edge_length", 9,
     R"(mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0 })",
     9, {"'edge_length'", "positive"}},
    {"edge_length_not_smaller_than_sheet", 9,
     R"(mesh = { generator = "sheet", width = 1, height = 0.5, edge_length = 0.5 })",
     9, {"'edge_length'", "smaller than"}},
    {"edge_length_not_smaller_than_cylinder", 9,
     R"(mesh = { generator = "cylinder", radius = 0.05, height = 1, edge_length = 0.1 })",
     9, {"'edge_length'", "smaller than"}},
    {"edge_length_not_smaller_than_sphere", 9,
     R"(mesh = { generator = "sphere", radius = 0.05, edge_length = 0.05 })",
     9, {"'edge_length'", "smaller than"}},
    {"panel_angle_above_a_turn", 9,
     R"(mesh = { generator = "cylindrical_panel", radius = 1, height = 1, angle_degrees = 400, edge_length = 0.1 })",
     9, {"'angle_degrees' in [shell.mesh]", "(0, 360]", "got 400"}},
    {"panel_edge_not_below_arc", 9,
     R"(mesh = { generator = "cylindrical_panel", radius = 1, height = 1, angle_degrees = 5, edge_length = 0.1 })",
     9, {"'edge_length'", "smaller than the panel's arc length and height"}},
    {"spherical_panel_without_polar_min", 9,
     R"(mesh = { generator = "spherical_panel", radius = 1, edge_length = 0.1 })",
     9, {"missing required key 'polar_min_degrees' in [shell.mesh]"}},
    {"spherical_panel_max_below_min", 9,
     R"(mesh = { generator = "spherical_panel", radius = 1, polar_min_degrees = 60, polar_max_degrees = 30, edge_length = 0.1 })",
     9, {"'polar_max_degrees' in [shell.mesh]", "(60, 180)"}},
    {"spherical_panel_key_of_cylinder", 9,
     R"(mesh = { generator = "spherical_panel", radius = 1, polar_min_degrees = 10, height = 2, edge_length = 0.1 })",
     9, {"unknown key 'height' in [shell.mesh]"}},
    {"negative_width", 9,
     R"(mesh = { generator = "sheet", width = -1, height = 1, edge_length = 0.1 })",
     9, {"'width'", "positive"}},
    {"zero_max_iterations", 6, "max_iterations = 0", 6, {"'max_iterations' in [solver]"}},
    {"negative_tolerance", 6, "tolerance = -1e-4", 6, {"'tolerance' in [solver]", "positive"}},
    {"box_min_above_max", 13,
     "box = { min = [1, -1, -1], max = [-0.4, 1, 1] }",
     13, {"'max' in [shell.pin.box]", "min [1, -1, -1]"}},
    {"box_without_max", 13,
     "box = { min = [1, -1, -1] }",
     13, {"missing required key 'max' in [shell.pin.box]"}},
    {"end_before_start", 16, "end = -1", 16, {"'end' in [shell.pin.motion]", "at least start"}},
    {"zero_motion_axis", 17, "axis = [0, 0, 0]", 17, {"'axis' in [shell.pin.motion]", "nonzero"}},
    {"zero_placement_axis", 8,
     "name = \"sheet\"\nplacement = { rotation_axis = [0, 0, 0], rotation_degrees = 90 }",
     9, {"'rotation_axis' in [shell.placement]", "nonzero"}},
    {"misspelt_bending_model", 8,
     "name = \"sheet\"\nbending = \"midege\"",
     9, {"unknown bending 'midege' in [shell]", "did you mean 'midedge'?",
         "expected one of 'hinge', 'midedge'"}},
    {"unknown_bending_model", 8,
     "name = \"sheet\"\nbending = \"discrete shells\"",
     9, {"unknown bending 'discrete shells' in [shell]", "expected one of 'hinge', 'midedge'"}},
    {"bending_in_material", 10,
     R"(material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3, bending = "hinge" })",
     10, {"unknown key 'bending' in [shell.material]"}},
    {"zero_scale", 8,
     "name = \"sheet\"\nplacement = { scale = 0 }",
     9, {"'scale' in [shell.placement]", "positive"}},
    {"empty_pin_components", 12,
     "name = \"left\"\ncomponents = []",
     13, {"'components' in [shell.pin]", "non-empty list", "'x', 'y', 'z'"}},
    {"unknown_pin_component", 12,
     "name = \"left\"\ncomponents = [\"x\", \"w\"]",
     13, {"unknown component 'w' in 'components' in [shell.pin]", "expected one of 'x', 'y', 'z'"}},
    {"upper_case_pin_component", 12,
     "name = \"left\"\ncomponents = [\"Z\"]",
     13, {"unknown component 'Z'", "did you mean 'z'?"}},
    {"repeated_pin_component", 12,
     "name = \"left\"\ncomponents = [\"x\", \"y\", \"x\"]",
     13, {"'components' in [shell.pin]", "distinct", "'x' is listed twice"}},
    {"pin_components_not_strings", 12,
     "name = \"left\"\ncomponents = \"x\"",
     13, {"expected an array of strings for 'components'"}},
    {"pin_component_misspelt_key", 12,
     "name = \"left\"\ncomponent = [\"x\"]",
     13, {"unknown key 'component' in [shell.pin]", "did you mean 'components'?"}},
    {"no_selector", 13,
     "",
     11, {"missing a vertex selector in [shell.pin]", "'box'", "'vertices'"}},
    {"two_selectors", 20,
     "boundary_loop = 0",
     21, {"several vertex selectors", "'boundary_loop', 'vertices'"}},
    {"negative_vertex", 21, "vertices = [0, -5]", 21, {"'vertices' in [shell.load]", "-5"}},
    {"empty_vertex_list", 21, "vertices = []", 21, {"'vertices' in [shell.load]", "non-empty"}},
    {"negative_boundary_loop", 21, "boundary_loop = -1", 21, {"'boundary_loop'", "-1"}},
    {"holes_on_structured_sheet", 9,
     R"(mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1, structured = true, holes = [{ center = [0, 0], radius = 0.1 }] })",
     9, {"'holes'", "structured = false"}},
    {"hole_outside_sheet", 9,
     R"(mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1, holes = [{ center = [0.45, 0], radius = 0.1 }] })",
     9, {"'radius' in [shell.mesh.holes]", "inside"}},
    {"overlapping_holes", 9,
     R"(mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1, holes = [{ center = [0, 0], radius = 0.2 }, { center = [0.3, 0], radius = 0.15 }] })",
     9, {"'radius' in [shell.mesh.holes]", "overlap"}},
    {"file_and_generator", 9,
     R"(mesh = { file = "a.obj", generator = "sheet" })",
     9, {"either 'file' or 'generator'"}},
    {"neither_file_nor_generator", 9,
     R"(mesh = { width = 1 })",
     9, {"missing 'file' or 'generator' in [shell.mesh]"}},
    {"unsupported_mesh_format", 9,
     R"(mesh = { file = "shape.stl" })",
     9, {"'file' in [shell.mesh]", ".obj, .ply or .off"}},
    {"shell_is_not_an_array", 7, "[shell]", 7, {"array of tables for 'shell'"}},
    {"empty_shell_name", 8, R"(name = "")", 8, {"'name' in [shell]", "non-empty"}},
    {"syntax_error", 15, "start = = 0", 15, {"TOML syntax error"}},
    {"duplicate_key", 16, "start = 1", 16, {"TOML syntax error", "start"}},
    {"inline_table_over_lines", 9,
     "mesh = { generator = \"sheet\",\n  width = 1, height = 1, edge_length = 0.1 }",
     9, {"TOML syntax error", "must fit on one line"}},
    // clang-format on
};

class BadScene : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadScene, IsAnInputErrorAtTheLineNamingTheKey) {
  const BadCase& c = GetParam();
  const fs::path dir = test::fresh_temp_dir(std::string("bad_scene_") + c.name);
  const fs::path path = test::write_file(dir / "bad.toml", scene_with(c.edited_line, c.text));
  try {
    read_scene(path);
    FAIL() << "no error for:\n" << scene_with(c.edited_line, c.text);
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path.string() + ":" + std::to_string(c.error_line) + ": ", 0), 0u)
        << message;
    for (const std::string& fragment : c.fragments)
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "'" << fragment << "' not in: " << message;
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, BadScene, ::testing::ValuesIn(kBadCases),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ReadScene, TheValidBaseOfTheBadCasesLoads) {
  const fs::path dir = test::fresh_temp_dir("bad_scene_base");
  const Scene scene = read_scene(test::write_file(dir / "good.toml", scene_with(0, "")));
  ASSERT_EQ(scene.shells.size(), 1u);
  EXPECT_EQ(scene.shells[0].pins.size(), 1u);
  EXPECT_EQ(scene.shells[0].loads.size(), 1u);
}

// Found by fuzz_scene: a mesh file name longer than the OS allows (ENAMETOOLONG) escaped as
// std::filesystem::filesystem_error instead of an InputError at the key's line.
TEST(ReadScene, MeshFileNameTooLongIsAnInputErrorAtItsLine) {
  const fs::path dir = test::fresh_temp_dir("long_mesh_name");
  const std::string name = std::string(300, 'k') + ".obj";
  const fs::path path = test::write_file(
      dir / "scene.toml", scene_with(9, "mesh = { file = \"" + name + "\" }"));
  try {
    read_scene(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path.string() + ":9: ", 0), 0u) << message;
    EXPECT_NE(message.find(std::strerror(ENAMETOOLONG)), std::string::npos) << message;
  }
}

TEST(ReadScene, MissingMeshFileNamesTheSceneLineAndTheResolvedPath) {
  const fs::path dir = test::fresh_temp_dir("missing_mesh");
  const fs::path path =
      test::write_file(dir / "scene.toml", scene_with(9, R"(mesh = { file = "meshes/gone.obj" })"));
  try {
    read_scene(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path.string() + ":9: ", 0), 0u) << message;
    EXPECT_NE(message.find("'meshes/gone.obj'"), std::string::npos) << message;
    const std::string resolved =
        fs::absolute(dir / "meshes" / "gone.obj").lexically_normal().string();
    EXPECT_NE(message.find(resolved), std::string::npos) << message;
  }
}

TEST(ReadScene, MissingSceneFileIsAnInputError) {
  const fs::path path = test::fresh_temp_dir("missing_scene") / "nowhere.toml";
  try {
    read_scene(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

TEST(ReadScene, SceneWithoutShellsIsAnInputError) {
  const fs::path dir = test::fresh_temp_dir("no_shell");
  const fs::path path = test::write_file(dir / "empty.toml", "name = \"empty\"\n");
  try {
    read_scene(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find("[[shell]]"), std::string::npos) << message;
  }
}

TEST(ReadScene, RepeatedNamesAreInputErrors) {
  const fs::path dir = test::fresh_temp_dir("repeated_names");
  std::string twice = scene_with(0, "");
  twice += "[[shell.pin]]\nname = \"left\"\nvertices = [1]\n";  // lines 23..25
  try {
    read_scene(test::write_file(dir / "pins.toml", twice));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("pins.toml:24: pin name 'left' is used twice"), std::string::npos)
        << message;
  }
  std::string shells = scene_with(0, "");
  shells += "[[shell]]\nname = \"sheet\"\n" + kValidLines[8] + "\n" + kValidLines[9] + "\n";
  try {
    read_scene(test::write_file(dir / "shells.toml", shells));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("shells.toml:24: shell name 'sheet' is used twice"), std::string::npos)
        << message;
  }
}

// ---------------------------------------------------------------------------------------------
// Contact and colliders

constexpr const char* kShellLines = R"([[shell]]
name = "cloth"
mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.1 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 1e-3 }
)";  // lines 1..4

TEST(ReadScene, ReadsContactSettingsAndCollidersAsWritten) {
  const fs::path dir = test::fresh_temp_dir("read_contact");
  const Scene scene =
      read_scene(test::write_file(dir / "contact.toml", std::string(kShellLines) + R"(
[contact]
enabled = true
self_contact = true
activation_distance = 2e-3
thickness = 1e-4
stiffness = 1e5
friction = 0.4
friction_slip_velocity = 2e-4
skip_when_apart = false
ccd = { rescaling = 0.8, ratio_bound = 0.999, max_iterations = 500 }

[[contact.pair]]
bodies = ["cloth", "ball"]
friction = 0.1

[[collider]]
name = "ball"
mesh = { generator = "sphere", radius = 0.3, edge_length = 0.05 }
placement = { translation = [0, 0, -0.4] }

[[collider]]
name = "plate"
mesh = { generator = "sheet", width = 2, height = 2, edge_length = 0.5 }

[[collider.motion]]
start = 0.5
end = 1.5
translation = [0, 0, -0.2]
)"));
  const ContactSettings& contact = scene.contact;
  EXPECT_EQ(contact.enabled, std::optional<bool>(true));
  EXPECT_TRUE(contact.self_contact);
  EXPECT_EQ(contact.activation_distance, std::optional<double>(2e-3));
  EXPECT_EQ(contact.thickness, 1e-4);
  EXPECT_EQ(contact.stiffness, std::optional<double>(1e5));
  EXPECT_EQ(contact.friction, 0.4);
  EXPECT_EQ(contact.friction_slip_velocity, std::optional<double>(2e-4));
  ASSERT_EQ(contact.pair_friction.size(), 1u);  // names a collider given further down
  EXPECT_EQ(contact.pair_friction[0].bodies[0], "cloth");
  EXPECT_EQ(contact.pair_friction[0].bodies[1], "ball");
  EXPECT_EQ(contact.pair_friction[0].friction, 0.1);
  EXPECT_FALSE(contact.skip_when_apart);
  EXPECT_EQ(contact.ccd_rescaling, 0.8);
  EXPECT_EQ(contact.ccd_ratio_bound, 0.999);
  EXPECT_EQ(contact.ccd_max_iterations, 500);
  ASSERT_EQ(scene.colliders.size(), 2u);
  EXPECT_EQ(scene.colliders[0].name, "ball");
  EXPECT_EQ(scene.colliders[0].mesh.kind, MeshSource::Kind::Sphere);
  EXPECT_EQ(scene.colliders[0].mesh.sphere.radius, 0.3);
  expect_vector(scene.colliders[0].mesh.translation, {0, 0, -0.4});
  EXPECT_TRUE(scene.colliders[0].motions.empty());
  EXPECT_EQ(scene.colliders[1].mesh.kind, MeshSource::Kind::Sheet);
  ASSERT_EQ(scene.colliders[1].motions.size(), 1u);
  EXPECT_EQ(scene.colliders[1].motions[0].start_time, 0.5);
  expect_vector(scene.colliders[1].motions[0].translation, {0, 0, -0.2});
}

TEST(ReadScene, ContactDefaultsLeaveTheChoicesToTheSimulation) {
  const fs::path dir = test::fresh_temp_dir("contact_defaults");
  const Scene scene = read_scene(test::write_file(dir / "plain.toml", kShellLines));
  const ContactSettings defaults;
  EXPECT_FALSE(scene.contact.enabled.has_value());
  EXPECT_FALSE(scene.contact.self_contact);
  EXPECT_FALSE(scene.contact.activation_distance.has_value());
  EXPECT_FALSE(scene.contact.stiffness.has_value());
  EXPECT_EQ(scene.contact.thickness, 0.0);
  EXPECT_EQ(scene.contact.friction, 0.0);
  EXPECT_TRUE(scene.contact.pair_friction.empty());
  EXPECT_FALSE(scene.contact.friction_slip_velocity.has_value());
  EXPECT_TRUE(scene.contact.skip_when_apart);
  EXPECT_EQ(scene.contact.ccd_rescaling, defaults.ccd_rescaling);
  EXPECT_EQ(scene.contact.ccd_ratio_bound, defaults.ccd_ratio_bound);
  EXPECT_TRUE(scene.colliders.empty());
}

TEST(ReadScene, BadContactAndColliderEntriesNameTheirFileLineAndKey) {
  const fs::path dir = test::fresh_temp_dir("bad_contact");
  // Each text is appended after the shell (lines 1..4), so its first line is line 5.
  const std::vector<std::tuple<std::string, int, std::string>> cases = {
      {"[contact]\nactivation_distance = 0", 6, "'activation_distance' in [contact]"},
      {"[contact]\nthickness = -1e-3", 6, "'thickness' in [contact]"},
      {"[contact]\nstiffness = -5", 6, "'stiffness' in [contact]"},
      {"[contact]\nfriction = -0.1", 6, "'friction' in [contact]"},
      {"[contact]\nself_contact = 1", 6, "true or false"},
      {"[contact]\nfrcition = 0.3", 6, "did you mean 'friction'?"},
      {"[contact]\nfriction_slip_velocity = 0", 6, "'friction_slip_velocity' in [contact]"},
      {"[[contact.pair]]\nbodies = [\"cloth\", \"clth\"]\nfriction = 0.2", 6,
       "unknown body 'clth' in 'bodies' in [contact.pair]; did you mean 'cloth'?"},
      {"[[contact.pair]]\nbodies = [\"cloth\"]", 6, "'bodies' in [contact.pair] must be a list of two"},
      {"[[contact.pair]]\nbodies = [\"cloth\", 3]", 6, "expected a string for 'bodies'"},
      {"[[contact.pair]]\nbodies = [\"cloth\", \"cloth\"]\nfriction = -1", 7,
       "'friction' in [contact.pair]"},
      {"[[contact.pair]]\nbodies = [\"cloth\", \"cloth\"]\nmu = 1", 7,
       "unknown key 'mu' in [contact.pair]"},
      {"[[contact.pair]]\nbodies = [\"cloth\", \"cloth\"]\n[[contact.pair]]\nbodies = "
       "[\"cloth\", \"cloth\"]",
       8, "is given twice"},
      {"[contact]\nccd = { ratio_bound = 1.5 }", 6, "'ratio_bound' in [contact.ccd]"},
      {"[contact]\nccd = { max_iterations = 0 }", 6, "'max_iterations' in [contact.ccd]"},
      {"[[collider]]\nname = \"ball\"", 5, "missing required table 'mesh' in [collider]"},
      {"[[collider]]\nname = \"cloth\"\nmesh = { generator = \"sphere\", radius = 1, "
       "edge_length = 0.5 }",
       6, "shell or collider name 'cloth' is used twice"},
      {"[[collider]]\nname = \"ball\"\nmesh = { generator = \"sphere\", radius = 1, "
       "edge_length = 0.5 }\nmass = 3",
       8, "unknown key 'mass' in [collider]"},
      {"[[collider]]\nname = \"ball\"\nmesh = { generator = \"sphere\", radius = 1, "
       "edge_length = 0.5 }\n[[collider.motion]]\nstart = 1\nend = 0",
       10, "'end' in [collider.motion]"},
  };
  int index = 0;
  for (const auto& [text, line, fragment] : cases)
    test::expect_scene_error(dir / fmt::format("case{}.toml", index++),
                             std::string(kShellLines) + text + "\n", line, fragment);
}

TEST(ReadScene, ReadsTheHierarchyTableAndItsDefaults) {
  const fs::path dir = test::fresh_temp_dir("read_hierarchy");
  const Scene plain = read_scene(test::write_file(dir / "plain.toml", kShellLines));
  EXPECT_EQ(plain.hierarchy.levels, 1);
  EXPECT_EQ(plain.hierarchy.vertex_ratio, 0.25);
  EXPECT_FALSE(plain.hierarchy.preview_tolerance.has_value());
  EXPECT_EQ(plain.hierarchy.preview_iterations, 2);
  EXPECT_FALSE(plain.hierarchy.refine_frame.has_value());

  const Scene scene =
      read_scene(test::write_file(dir / "hierarchy.toml", std::string(kShellLines) + R"(
[time]
frames = 12
[hierarchy]
levels = 3
vertex_ratio = 0.3
preview_tolerance = 2e-3
preview_iterations = 5
refine_frame = 7
)"));
  EXPECT_EQ(scene.hierarchy.levels, 3);
  EXPECT_EQ(scene.hierarchy.vertex_ratio, 0.3);
  EXPECT_EQ(scene.hierarchy.preview_tolerance, 2e-3);
  EXPECT_EQ(scene.hierarchy.preview_iterations, 5);
  EXPECT_EQ(scene.hierarchy.refine_frame, 7);
}

TEST(ReadScene, BadHierarchyEntriesNameTheirFileLineAndKey) {
  const fs::path dir = test::fresh_temp_dir("bad_hierarchy");
  // Each line follows the shell (lines 1..4), [time] and [hierarchy]: it is line 8.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"levels = 0", "'levels' in [hierarchy] must be at least 1"},
      {"vertex_ratio = 1", "'vertex_ratio' in [hierarchy] must be in (0, 1)"},
      {"preview_tolerance = 0", "'preview_tolerance' in [hierarchy] must be positive"},
      {"preview_iterations = 0", "'preview_iterations' in [hierarchy] must be at least 1"},
      {"refine_frame = 4", "'refine_frame' in [hierarchy] must be a frame in 1..3"},
      {"levles = 2", "did you mean 'levels'?"},
  };
  int index = 0;
  for (const auto& [line, fragment] : cases)
    test::expect_scene_error(
        dir / fmt::format("case{}.toml", index++),
        std::string(kShellLines) + "[time]\nframes = 3\n[hierarchy]\n" + line + "\n", 8, fragment);
}

}  // namespace
}  // namespace psq
